#include "lightmap/chart_param.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Sparse>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <complex>
#include <limits>
#include <numeric>

#include "core/error.h"

namespace lo::lightmap_internal {

namespace {

// A projection whose stretch is this close to 1 is kept without trying LSCM:
// LSCM could gain at most 0.1% there.
constexpr double kNearIsometric = 1e-3;
// A flattened triangle must keep at least this fraction of its 3D area (after
// the chart is scaled to its 3D area); less is a fold in the making, and a
// triangle this thin in UV would get no texel of its own.
constexpr double kMinAreaRatio = 1e-6;
// Halving the cone below this gains nothing; split along the principal axis.
constexpr double kMinConeDegrees = 1.0;

constexpr double kPiD = 3.14159265358979323846;

D3 cornerPosition(const Scene& scene, size_t t, int k) {
  return D3(scene.positions[scene.indices[3 * t + size_t(k)]]);
}

// Twice the signed area of the 2D triangle (x0 y0 x1 y1 x2 y2).
double signedArea2(const double* p) {
  return (p[2] - p[0]) * (p[5] - p[1]) - (p[4] - p[0]) * (p[3] - p[1]);
}

// Any unit vector orthogonal to unit n, and n x t, so that (t, b, n) is a
// right-handed frame: projecting onto (t, b) keeps counter-clockwise about n
// counter-clockwise in the plane.
void tangentFrame(const D3& n, D3& t, D3& b) {
  const D3 axis =
      std::abs(n.x) < 0.57 ? D3{1, 0, 0} : (std::abs(n.y) < 0.57 ? D3{0, 1, 0} : D3{0, 0, 1});
  t = normalize(cross(axis, n));
  b = cross(n, t);
}

struct UnionFind {
  std::vector<int32_t> parent;
  explicit UnionFind(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int32_t find(int32_t a) {
    while (parent[size_t(a)] != a) {
      parent[size_t(a)] = parent[size_t(parent[size_t(a)])];
      a = parent[size_t(a)];
    }
    return a;
  }
  // The smaller root wins, so the result does not depend on the union order.
  void unite(int32_t a, int32_t b) {
    a = find(a);
    b = find(b);
    if (a == b) return;
    if (a < b) std::swap(a, b);
    parent[size_t(a)] = b;
  }
};

}  // namespace

// ---------------------------------------------------------------------------
// Geometry and topology

TriangleGeometry triangleGeometry(const Scene& scene) {
  const size_t n = scene.triangleCount();
  TriangleGeometry g;
  g.normal.resize(n);
  g.area.resize(n);
  g.degenerate.assign(n, 0);
  double scale = 0;
  for (const Vec3& p : scene.positions) {
    scale = std::max({scale, std::abs(double(p.x)), std::abs(double(p.y)), std::abs(double(p.z))});
  }
  const double minHeight = kDegenerateHeight * scale;
  for (size_t t = 0; t < n; ++t) {
    const D3 a = cornerPosition(scene, t, 0), b = cornerPosition(scene, t, 1),
             c = cornerPosition(scene, t, 2);
    const D3 nrm = cross(b - a, c - a);
    const double twiceArea = length(nrm);
    const double longest =
        std::sqrt(std::max({dot(b - a, b - a), dot(c - b, c - b), dot(a - c, a - c)}));
    g.area[t] = 0.5 * twiceArea;
    if (!(twiceArea > 0) || twiceArea <= minHeight * longest) {
      g.degenerate[t] = 1;
      g.area[t] = 0;
      continue;
    }
    g.normal[t] = nrm * (1.0 / twiceArea);
  }
  return g;
}

ChartTopology buildChartTopology(const Scene& scene) {
  ChartTopology topo;
  topo.geometry = triangleGeometry(scene);
  const size_t nt = scene.triangleCount();
  const size_t nv = scene.positions.size();

  // Weld: sort the vertices by position (ties by index), equal runs share an id.
  std::vector<int32_t> order(nv);
  std::iota(order.begin(), order.end(), 0);
  auto less = [&](int32_t a, int32_t b) {
    const Vec3& p = scene.positions[size_t(a)];
    const Vec3& q = scene.positions[size_t(b)];
    if (p.x != q.x) return p.x < q.x;
    if (p.y != q.y) return p.y < q.y;
    if (p.z != q.z) return p.z < q.z;
    return a < b;
  };
  std::sort(order.begin(), order.end(), less);
  topo.weld.assign(nv, -1);
  int32_t ids = -1;
  for (size_t i = 0; i < nv; ++i) {
    if (i == 0 || scene.positions[size_t(order[i])] != scene.positions[size_t(order[i - 1])]) ++ids;
    topo.weld[size_t(order[i])] = ids;
  }

  // An edge's users: the non-degenerate triangles' half-edges keyed by their
  // welded end points, sorted so that an edge's users lie side by side
  // (O(n log n) whatever the valence; scanning the triangles around an end
  // point for the other was quadratic in the valence: a fan of 10^5
  // triangles around one vertex took minutes).
  auto weldOf = [&](size_t t, int k) { return topo.weld[scene.indices[3 * t + size_t(k)]]; };
  struct HalfEdge {
    uint64_t key;  ///< the smaller welded end point, then the larger
    int32_t triangle;
    int32_t corner;  ///< the edge runs from this corner to the next
    bool forward;    ///< it runs from the smaller end point to the larger
  };
  std::vector<HalfEdge> halfEdges;
  halfEdges.reserve(3 * nt);
  for (size_t t = 0; t < nt; ++t) {
    if (topo.geometry.degenerate[t]) continue;
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = uint32_t(weldOf(t, k)), b = uint32_t(weldOf(t, (k + 1) % 3));
      const uint64_t key = a < b ? (uint64_t(a) << 32 | b) : (uint64_t(b) << 32 | a);
      halfEdges.push_back({key, int32_t(t), k, a < b});
    }
  }
  std::sort(halfEdges.begin(), halfEdges.end(), [](const HalfEdge& x, const HalfEdge& y) {
    return x.key != y.key
               ? x.key < y.key
               : (x.triangle != y.triangle ? x.triangle < y.triangle : x.corner < y.corner);
  });
  // Neighbours across an edge that exactly two triangles use, in opposite
  // directions (manifold and consistently oriented); any other edge is a seam.
  topo.neighbour.assign(3 * nt, -1);
  for (size_t i = 0; i < halfEdges.size();) {
    size_t j = i + 1;
    while (j < halfEdges.size() && halfEdges[j].key == halfEdges[i].key) ++j;
    const HalfEdge& e = halfEdges[i];
    const HalfEdge& f = halfEdges[i + 1 < j ? i + 1 : i];
    if (j - i == 2 && e.forward != f.forward) {
      topo.neighbour[3 * size_t(e.triangle) + size_t(e.corner)] = f.triangle;
      topo.neighbour[3 * size_t(f.triangle) + size_t(f.corner)] = e.triangle;
    }
    i = j;
  }

  for (size_t t = 0; t < nt; ++t) {
    if (!topo.geometry.degenerate[t]) topo.seedOrder.push_back(int32_t(t));
  }
  const std::vector<double>& area = topo.geometry.area;
  std::sort(topo.seedOrder.begin(), topo.seedOrder.end(), [&](int32_t a, int32_t b) {
    return area[size_t(a)] != area[size_t(b)] ? area[size_t(a)] > area[size_t(b)] : a < b;
  });
  topo.seedRank.assign(nt, -1);
  for (size_t i = 0; i < topo.seedOrder.size(); ++i)
    topo.seedRank[size_t(topo.seedOrder[i])] = int32_t(i);
  return topo;
}

double triangleStretchSquared(const D3 q[3], const double p[6]) {
  // Sander et al. 2001, eq. (1): S_s and S_t, the partial derivatives of the
  // 2D -> 3D map; L2^2 = (|S_s|^2 + |S_t|^2) / 2.
  const double a2 = signedArea2(p);
  const double s0 = p[0], t0 = p[1], s1 = p[2], t1 = p[3], s2 = p[4], t2 = p[5];
  const D3 ss = (q[0] * (t1 - t2) + q[1] * (t2 - t0) + q[2] * (t0 - t1)) * (1.0 / a2);
  const D3 st = (q[0] * (s2 - s1) + q[1] * (s0 - s2) + q[2] * (s1 - s0)) * (1.0 / a2);
  return 0.5 * (dot(ss, ss) + dot(st, st));
}

// ---------------------------------------------------------------------------
// Flattening

/// A chart's own vertices: corners are one vertex when they share a welded
/// position *and* are joined through edges inside the chart, so a chart that
/// touches itself at a vertex (a bowtie) or across a seam is cut open there.
struct ChartFlattener::LocalMesh {
  std::vector<int32_t> cornerVertex;  ///< 3 per chart triangle
  std::vector<D3> position;           ///< per local vertex
};

namespace {

// A flattening of a chart: one 2D point per local vertex, scaled so the
// chart's 2D area equals its 3D area, or invalid (a fold or a solver failure).
struct Flattening {
  bool valid = false;
  std::vector<double> xy;  ///< 2 per local vertex
  double stretch = std::numeric_limits<double>::infinity();
  double area = 0;
};

void cornerXY(const std::vector<double>& xy, const std::vector<int32_t>& cornerVertex, size_t i,
              double p[6]) {
  for (int k = 0; k < 3; ++k) {
    const size_t v = size_t(cornerVertex[3 * i + size_t(k)]);
    p[2 * k] = xy[2 * v];
    p[2 * k + 1] = xy[2 * v + 1];
  }
}

}  // namespace

int32_t ChartFlattener::newStamp() {
  if (stamp_ >= std::numeric_limits<int32_t>::max() - 1) {
    std::fill(member_.begin(), member_.end(), 0);
    std::fill(assigned_.begin(), assigned_.end(), 0);
    stamp_ = 0;
  }
  return ++stamp_;
}

ChartFlattener::ChartFlattener(const Scene& scene, const ChartTopology& topology, double maxStretch)
    : scene_(scene), topo_(topology), maxStretch_(maxStretch) {
  const size_t nt = scene.triangleCount();
  member_.assign(nt, 0);
  assigned_.assign(nt, 0);
  local_.assign(nt, -1);
}

void ChartFlattener::sortBySeedRank(std::vector<int32_t>& faces) const {
  std::sort(faces.begin(), faces.end(), [&](int32_t a, int32_t b) {
    return topo_.seedRank[size_t(a)] < topo_.seedRank[size_t(b)];
  });
}

std::vector<std::vector<int32_t>> ChartFlattener::grow(const std::vector<int32_t>& faces,
                                                       double cosCone) {
  // Region growing (breadth first) from seeds in seed order: a neighbour joins
  // when its normal is within the cone of the chart's running area-weighted
  // mean normal. `faces` must be in seed order.
  const int32_t member = newStamp();
  const int32_t taken = newStamp();
  for (int32_t f : faces) member_[size_t(f)] = member;
  const std::vector<D3>& normal = topo_.geometry.normal;
  const std::vector<double>& area = topo_.geometry.area;
  std::vector<std::vector<int32_t>> charts;
  for (int32_t seed : faces) {
    if (assigned_[size_t(seed)] == taken) continue;
    std::vector<int32_t> chart{seed};
    assigned_[size_t(seed)] = taken;
    D3 sum = normal[size_t(seed)] * area[size_t(seed)];
    for (size_t head = 0; head < chart.size(); ++head) {
      const size_t f = size_t(chart[head]);
      for (int k = 0; k < 3; ++k) {
        const int32_t g = topo_.neighbour[3 * f + size_t(k)];
        if (g < 0 || member_[size_t(g)] != member || assigned_[size_t(g)] == taken) continue;
        const double len = length(sum);
        const D3 mean = len > 0 ? sum * (1.0 / len) : normal[size_t(seed)];
        if (dot(normal[size_t(g)], mean) < cosCone) continue;
        assigned_[size_t(g)] = taken;
        sum += normal[size_t(g)] * area[size_t(g)];
        chart.push_back(g);
      }
    }
    charts.push_back(std::move(chart));
  }
  return charts;
}

void ChartFlattener::buildLocalMesh(const std::vector<int32_t>& faces, LocalMesh& mesh) {
  const int32_t member = newStamp();
  for (size_t i = 0; i < faces.size(); ++i) {
    member_[size_t(faces[i])] = member;
    local_[size_t(faces[i])] = int32_t(i);
  }
  auto weldOf = [&](size_t t, int k) { return topo_.weld[scene_.indices[3 * t + size_t(k)]]; };
  UnionFind corners(3 * faces.size());
  for (size_t i = 0; i < faces.size(); ++i) {
    const size_t f = size_t(faces[i]);
    for (int k = 0; k < 3; ++k) {
      const int32_t g = topo_.neighbour[3 * f + size_t(k)];
      if (g < 0 || g < int32_t(f) || member_[size_t(g)] != member) continue;
      const int32_t a = weldOf(f, k), b = weldOf(f, (k + 1) % 3);
      const size_t j = size_t(local_[size_t(g)]);
      for (int c = 0; c < 3; ++c) {
        const int32_t w = weldOf(size_t(g), c);
        if (w == a) corners.unite(int32_t(3 * i + size_t(k)), int32_t(3 * j + size_t(c)));
        if (w == b) corners.unite(int32_t(3 * i + size_t((k + 1) % 3)), int32_t(3 * j + size_t(c)));
      }
    }
  }
  mesh.cornerVertex.assign(3 * faces.size(), -1);
  mesh.position.clear();
  std::vector<int32_t> vertexOfRoot(3 * faces.size(), -1);
  for (size_t c = 0; c < 3 * faces.size(); ++c) {
    const size_t root = size_t(corners.find(int32_t(c)));
    if (vertexOfRoot[root] < 0) {
      vertexOfRoot[root] = int32_t(mesh.position.size());
      mesh.position.push_back(cornerPosition(scene_, size_t(faces[c / 3]), int(c % 3)));
    }
    mesh.cornerVertex[c] = vertexOfRoot[root];
  }
}

namespace {

// Checks orientation, scales to the 3D area and measures the stretch.
Flattening evaluate(const std::vector<D3>& position, const std::vector<int32_t>& cornerVertex,
                    const std::vector<double>& triArea, std::vector<double> xy) {
  Flattening out;
  const size_t nt = triArea.size();
  double area2 = 0, area3 = 0;
  for (size_t i = 0; i < nt; ++i) {
    double p[6];
    cornerXY(xy, cornerVertex, i, p);
    const double a = 0.5 * signedArea2(p);
    if (!(a > 0)) return out;  // a fold (or NaN from the solver)
    area2 += a;
    area3 += triArea[i];
  }
  const double scale = std::sqrt(area3 / area2);
  for (double& c : xy) c *= scale;
  double sum = 0;
  for (size_t i = 0; i < nt; ++i) {
    double p[6];
    cornerXY(xy, cornerVertex, i, p);
    if (0.5 * signedArea2(p) <= kMinAreaRatio * triArea[i]) return out;
    const D3 q[3] = {position[size_t(cornerVertex[3 * i])],
                     position[size_t(cornerVertex[3 * i + 1])],
                     position[size_t(cornerVertex[3 * i + 2])]};
    sum += triangleStretchSquared(q, p) * triArea[i];
  }
  out.valid = std::isfinite(sum);
  out.stretch = std::sqrt(sum / area3);
  out.area = area3;
  out.xy = std::move(xy);
  return out;
}

// Orthogonal projection onto the plane of unit normal n.
std::vector<double> project(const std::vector<D3>& position, const D3& n) {
  D3 t, b;
  tangentFrame(n, t, b);
  std::vector<double> xy(2 * position.size());
  const D3 origin = position[0];
  for (size_t v = 0; v < position.size(); ++v) {
    const D3 d = position[v] - origin;
    xy[2 * v] = dot(d, t);
    xy[2 * v + 1] = dot(d, b);
  }
  return xy;
}

// Least-squares conformal map (Lévy et al. 2002, §3): per triangle, in its own
// orthonormal frame with corners (x_j, y_j), the conformality residual is
// sum_j m_j U_j with U_j = u_j + i v_j, m_j = W_j / sqrt(d_T),
// W_j = (x_{j+2} - x_{j+1}) + i (y_{j+2} - y_{j+1}) and d_T twice the area; it
// vanishes for every orientation-preserving similarity. The energy
// sum_T |sum_j m_j U_j|^2 = U^H K U with K_pq = sum_T conj(m_p) m_q is
// Hermitian positive definite over the free vertices of a connected chart
// with two pinned, and K_ff U_f = -K_fp U_p is solved by sparse LDL^H. The
// complex form has half the unknowns of the real one and a quarter of the
// non-zeros. Returns false on failure.
bool solveLscm(const std::vector<D3>& position, const std::vector<int32_t>& cornerVertex,
               std::vector<double>& xy) {
  using Complex = std::complex<double>;
  const size_t nv = position.size();
  const size_t nt = cornerVertex.size() / 3;
  if (nv < 3) return false;
  // Pins: the extremes along the longest axis of the chart's bounding box
  // (Lévy et al. 2002, §5), mapped to 0 and their distance on the real axis.
  D3 lo = position[0], hi = position[0];
  for (const D3& p : position) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  const D3 ext = hi - lo;
  const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
  auto coord = [axis](const D3& p) { return axis == 0 ? p.x : (axis == 1 ? p.y : p.z); };
  size_t pin0 = 0, pin1 = 0;
  for (size_t v = 1; v < nv; ++v) {
    if (coord(position[v]) < coord(position[pin0])) pin0 = v;
    if (coord(position[v]) > coord(position[pin1])) pin1 = v;
  }
  if (pin0 == pin1) return false;
  const Complex pinned0(0, 0), pinned1(length(position[pin1] - position[pin0]), 0);
  std::vector<int32_t> freeIndex(nv, -1);
  int32_t nFree = 0;
  for (size_t v = 0; v < nv; ++v) {
    if (v != pin0 && v != pin1) freeIndex[v] = nFree++;
  }

  std::vector<Eigen::Triplet<Complex>> triplets;
  triplets.reserve(6 * nt);
  Eigen::VectorXcd rhs = Eigen::VectorXcd::Zero(nFree);
  for (size_t i = 0; i < nt; ++i) {
    const size_t vtx[3] = {size_t(cornerVertex[3 * i]), size_t(cornerVertex[3 * i + 1]),
                           size_t(cornerVertex[3 * i + 2])};
    const D3 e1 = position[vtx[1]] - position[vtx[0]];
    const D3 e2 = position[vtx[2]] - position[vtx[0]];
    const double l1 = length(e1);
    const D3 ax = e1 * (1.0 / l1);
    const D3 ay = normalize(cross(normalize(cross(e1, e2)), ax));
    const double x[3] = {0, l1, dot(e2, ax)};
    const double y[3] = {0, 0, dot(e2, ay)};
    const double dT = l1 * y[2];
    if (!(dT > 0)) return false;
    const double s = 1.0 / std::sqrt(dT);
    Complex m[3];
    for (int j = 0; j < 3; ++j) {
      m[j] = Complex((x[(j + 2) % 3] - x[(j + 1) % 3]) * s, (y[(j + 2) % 3] - y[(j + 1) % 3]) * s);
    }
    for (int p = 0; p < 3; ++p) {
      const int32_t fp = freeIndex[vtx[p]];
      if (fp < 0) continue;
      for (int q = 0; q < 3; ++q) {
        const Complex k = std::conj(m[p]) * m[q];
        const int32_t fq = freeIndex[vtx[q]];
        if (fq < 0) {
          rhs[fp] -= k * (vtx[q] == pin0 ? pinned0 : pinned1);
        } else if (fp >= fq) {
          triplets.emplace_back(fp, fq, k);
        }
      }
    }
  }
  Eigen::SparseMatrix<Complex> system(nFree, nFree);
  system.setFromTriplets(triplets.begin(), triplets.end());
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<Complex>, Eigen::Lower> solver(system);
  if (solver.info() != Eigen::Success) return false;
  const Eigen::VectorXcd sol = solver.solve(rhs);
  if (solver.info() != Eigen::Success || !sol.allFinite()) return false;
  xy.assign(2 * nv, 0);
  for (size_t v = 0; v < nv; ++v) {
    const Complex z = freeIndex[v] >= 0 ? sol[freeIndex[v]] : (v == pin0 ? pinned0 : pinned1);
    xy[2 * v] = z.real();
    xy[2 * v + 1] = z.imag();
  }
  return true;
}

}  // namespace

void orientChart(std::vector<double>& xy, double& width, double& height, size_t* projections) {
  const size_t nv = xy.size() / 2;
  std::vector<size_t> order(nv);
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return xy[2 * a] != xy[2 * b]
               ? xy[2 * a] < xy[2 * b]
               : (xy[2 * a + 1] != xy[2 * b + 1] ? xy[2 * a + 1] < xy[2 * b + 1] : a < b);
  });
  // Andrew's monotone chain; collinear points dropped.
  auto turn = [&](size_t o, size_t a, size_t b) {
    return (xy[2 * a] - xy[2 * o]) * (xy[2 * b + 1] - xy[2 * o + 1]) -
           (xy[2 * a + 1] - xy[2 * o + 1]) * (xy[2 * b] - xy[2 * o]);
  };
  std::vector<size_t> hull(2 * nv);
  size_t k = 0;
  for (size_t i = 0; i < nv; ++i) {
    while (k >= 2 && turn(hull[k - 2], hull[k - 1], order[i]) <= 0) --k;
    hull[k++] = order[i];
  }
  for (size_t i = nv - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && turn(hull[k - 2], hull[k - 1], order[i]) <= 0) --k;
    hull[k++] = order[i];
  }
  hull.resize(k > 1 ? k - 1 : k);

  // Rotating calipers (Toussaint 1983): the hull is counter-clockwise, so as
  // the edge turns, the points farthest along it (max u), against it (min u)
  // and from it (max v) move forward around the hull, each once in all:
  // O(hull) projections. The scan of every hull point for every edge made
  // hull^2, hours for a chart whose outline has 10^6 vertices.
  const size_t h = hull.size();
  size_t count = 0;
  auto along = [&](size_t i, double dx, double dy) {
    ++count;
    const size_t q = hull[i % h];
    return dx * xy[2 * q] + dy * xy[2 * q + 1];
  };
  auto across = [&](size_t i, double dx, double dy) {
    ++count;
    const size_t q = hull[i % h];
    return -dy * xy[2 * q] + dx * xy[2 * q + 1];
  };
  double bestArea = std::numeric_limits<double>::infinity();
  double bestC = 1, bestS = 0;
  size_t maxU = 0, minU = 0, maxV = 0;
  bool started = false;
  for (size_t i = 0; i < h; ++i) {
    const size_t a = hull[i], b = hull[(i + 1) % h];
    double dx = xy[2 * b] - xy[2 * a], dy = xy[2 * b + 1] - xy[2 * a + 1];
    const double len = std::sqrt(dx * dx + dy * dy);
    if (!(len > 0)) continue;
    dx /= len;
    dy /= len;
    if (!started) {
      // The first edge's extremes by a scan; later edges move them on.
      for (size_t j = 1; j < h; ++j) {
        if (along(j, dx, dy) > along(maxU, dx, dy)) maxU = j;
        if (along(j, dx, dy) < along(minU, dx, dy)) minU = j;
        if (across(j, dx, dy) > across(maxV, dx, dy)) maxV = j;
      }
      started = true;
    }
    for (size_t step = 0; step < h && along(maxU + 1, dx, dy) >= along(maxU, dx, dy); ++step)
      maxU = (maxU + 1) % h;
    for (size_t step = 0; step < h && along(minU + 1, dx, dy) <= along(minU, dx, dy); ++step)
      minU = (minU + 1) % h;
    for (size_t step = 0; step < h && across(maxV + 1, dx, dy) >= across(maxV, dx, dy); ++step)
      maxV = (maxV + 1) % h;
    // The edge itself is the side the hull lies left of: least v at its ends.
    const double lowV = std::min(across(i, dx, dy), across(i + 1, dx, dy));
    const double area = (along(maxU, dx, dy) - along(minU, dx, dy)) * (across(maxV, dx, dy) - lowV);
    if (area < bestArea * (1 - 1e-9)) {
      bestArea = area;
      bestC = dx;
      bestS = dy;
    }
  }
  if (projections) *projections += count;
  double minX = INFINITY, maxX = -INFINITY, minY = INFINITY, maxY = -INFINITY;
  for (size_t v = 0; v < nv; ++v) {
    const double u = bestC * xy[2 * v] + bestS * xy[2 * v + 1];
    const double w = -bestS * xy[2 * v] + bestC * xy[2 * v + 1];
    xy[2 * v] = u;
    xy[2 * v + 1] = w;
    minX = std::min(minX, u);
    maxX = std::max(maxX, u);
    minY = std::min(minY, w);
    maxY = std::max(maxY, w);
  }
  width = maxX - minX;
  height = maxY - minY;
  const bool turn90 = height > width;
  for (size_t v = 0; v < nv; ++v) {
    const double u = xy[2 * v] - minX, w = xy[2 * v + 1] - minY;
    // A quarter turn, (u, w) -> (height - w, u), keeps the orientation.
    xy[2 * v] = turn90 ? height - w : u;
    xy[2 * v + 1] = turn90 ? u : w;
  }
  if (turn90) std::swap(width, height);
}

void ChartFlattener::flatten(const std::vector<int32_t>& faces, double coneDegrees,
                             std::vector<FlatChart>& out) {
  LocalMesh mesh;
  buildLocalMesh(faces, mesh);
  std::vector<double> triArea(faces.size());
  D3 sum;
  bool frontFacing = true;
  for (size_t i = 0; i < faces.size(); ++i) {
    triArea[i] = topo_.geometry.area[size_t(faces[i])];
    sum += topo_.geometry.normal[size_t(faces[i])] * triArea[i];
  }
  const D3 n = normalize(sum);
  for (int32_t f : faces) frontFacing = frontFacing && dot(topo_.geometry.normal[size_t(f)], n) > 0;

  // Planar charts (and single triangles) are projected: stretch 1 up to
  // rounding. Near-isometric projections are kept as they are.
  Flattening projection;
  if (frontFacing)
    projection = evaluate(mesh.position, mesh.cornerVertex, triArea, project(mesh.position, n));
  Flattening chosen;
  if (projection.valid && projection.stretch <= 1 + kNearIsometric) {
    chosen = std::move(projection);
  } else {
    std::vector<double> xy;
    if (solveLscm(mesh.position, mesh.cornerVertex, xy)) {
      chosen = evaluate(mesh.position, mesh.cornerVertex, triArea, std::move(xy));
    }
    if (!(chosen.valid && chosen.stretch <= maxStretch_) && projection.valid &&
        projection.stretch <= maxStretch_) {
      chosen = std::move(projection);
    }
  }
  if (!(chosen.valid && chosen.stretch <= maxStretch_)) {
    LO_CHECK_LT(size_t(1), faces.size());  // a single triangle always projects
    split(faces, coneDegrees, out);
    return;
  }
  FlatChart chart;
  chart.triangles = faces;
  orientChart(chosen.xy, chart.width, chart.height);
  chart.uv.resize(6 * faces.size());
  for (size_t i = 0; i < faces.size(); ++i)
    cornerXY(chosen.xy, mesh.cornerVertex, i, &chart.uv[6 * i]);
  chart.area = chosen.area;
  chart.stretch = chosen.stretch;
  out.push_back(std::move(chart));
}

std::vector<std::vector<int32_t>> ChartFlattener::principalHalves(
    const std::vector<int32_t>& faces) {
  // Area-weighted covariance of the centroids; its largest eigenvector is the
  // axis, the cut halves the area.
  const size_t n = faces.size();
  std::vector<D3> centroid(n);
  double total = 0;
  D3 mean;
  for (size_t i = 0; i < n; ++i) {
    const size_t t = size_t(faces[i]);
    centroid[i] = (cornerPosition(scene_, t, 0) + cornerPosition(scene_, t, 1) +
                   cornerPosition(scene_, t, 2)) *
                  (1.0 / 3.0);
    const double a = topo_.geometry.area[t];
    mean += centroid[i] * a;
    total += a;
  }
  mean = mean * (1.0 / total);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < n; ++i) {
    const D3 d = centroid[i] - mean;
    const Eigen::Vector3d e(d.x, d.y, d.z);
    cov += topo_.geometry.area[size_t(faces[i])] * e * e.transpose();
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  Eigen::Vector3d axis = eig.eigenvectors().col(2);
  Eigen::Index big = 0;
  axis.cwiseAbs().maxCoeff(&big);
  if (axis[big] < 0) axis = -axis;  // one sign, so the order does not depend on the solver's
  std::vector<std::pair<double, int32_t>> keyed(n);
  for (size_t i = 0; i < n; ++i) {
    keyed[i] = {axis[0] * centroid[i].x + axis[1] * centroid[i].y + axis[2] * centroid[i].z,
                faces[i]};
  }
  std::sort(keyed.begin(), keyed.end());
  size_t cut = 1;
  double acc = topo_.geometry.area[size_t(keyed[0].second)];
  while (cut + 1 < n && acc + topo_.geometry.area[size_t(keyed[cut].second)] <= 0.5 * total) {
    acc += topo_.geometry.area[size_t(keyed[cut].second)];
    ++cut;
  }
  std::vector<std::vector<int32_t>> halves(2);
  for (size_t i = 0; i < n; ++i) halves[i < cut ? 0 : 1].push_back(keyed[i].second);
  return halves;
}

void ChartFlattener::split(const std::vector<int32_t>& faces, double coneDegrees,
                           std::vector<FlatChart>& out) {
  // First regrow with half the cone (smaller, flatter charts); when that
  // keeps the chart whole, cut it along its principal axis.
  const double half = 0.5 * coneDegrees;
  std::vector<int32_t> sorted = faces;
  sortBySeedRank(sorted);
  if (half >= kMinConeDegrees) {
    std::vector<std::vector<int32_t>> parts = grow(sorted, std::cos(half * kPiD / 180.0));
    if (parts.size() >= 2) {
      for (const std::vector<int32_t>& part : parts) flatten(part, half, out);
      return;
    }
  }
  for (std::vector<int32_t>& halfFaces : principalHalves(sorted)) {
    sortBySeedRank(halfFaces);
    for (const std::vector<int32_t>& part : grow(halfFaces, -2.0)) flatten(part, half, out);
  }
}

std::vector<FlatChart> ChartFlattener::run(double coneDegrees) {
  std::vector<FlatChart> out;
  const double cosCone = std::cos(std::min(coneDegrees, 180.0) * kPiD / 180.0);
  std::vector<std::vector<int32_t>> charts = grow(topo_.seedOrder, cosCone);
  absorbSingles(charts, cosCone);
  for (const std::vector<int32_t>& chart : charts) flatten(chart, coneDegrees, out);
  return out;
}

void ChartFlattener::absorbSingles(std::vector<std::vector<int32_t>>& charts,
                                   double cosCone) const {
  // The growth leaves a triangle alone when its neighbours went to charts
  // whose mean normal had drifted away by the time they reached it. Such a
  // triangle joins the neighbouring chart (of two or more triangles) whose
  // final mean normal is closest, if that is within the cone: fewer
  // one-triangle charts, fewer seams. Folds sharper than the cone stay alone.
  const std::vector<D3>& normal = topo_.geometry.normal;
  const std::vector<double>& area = topo_.geometry.area;
  std::vector<int32_t> chartOf(normal.size(), -1);
  std::vector<D3> sum(charts.size());
  for (size_t c = 0; c < charts.size(); ++c) {
    for (int32_t f : charts[c]) {
      chartOf[size_t(f)] = int32_t(c);
      sum[c] += normal[size_t(f)] * area[size_t(f)];
    }
  }
  bool moved = false;
  for (size_t c = 0; c < charts.size(); ++c) {
    if (charts[c].size() != 1) continue;
    const size_t f = size_t(charts[c][0]);
    int32_t best = -1;
    double bestDot = cosCone;
    for (int k = 0; k < 3; ++k) {
      const int32_t g = topo_.neighbour[3 * f + size_t(k)];
      if (g < 0) continue;
      const int32_t other = chartOf[size_t(g)];
      if (other < 0 || other == int32_t(c) || charts[size_t(other)].size() < 2) continue;
      const double d = dot(normal[f], normalize(sum[size_t(other)]));
      if (d > bestDot || (d == bestDot && (best < 0 || other < best))) {
        best = other;
        bestDot = d;
      }
    }
    if (best < 0) continue;
    charts[size_t(best)].push_back(int32_t(f));
    sum[size_t(best)] += normal[f] * area[f];
    chartOf[f] = best;
    charts[c].clear();
    moved = true;
  }
  if (moved) {
    charts.erase(std::remove_if(charts.begin(), charts.end(),
                                [](const std::vector<int32_t>& c) { return c.empty(); }),
                 charts.end());
  }
}

std::vector<FlatChart> ChartFlattener::splitInHalves(const std::vector<int32_t>& triangles,
                                                     double coneDegrees) {
  LO_CHECK_LT(size_t(1), triangles.size());
  std::vector<FlatChart> out;
  std::vector<int32_t> sorted = triangles;
  sortBySeedRank(sorted);
  for (std::vector<int32_t>& halfFaces : principalHalves(sorted)) {
    sortBySeedRank(halfFaces);
    for (const std::vector<int32_t>& part : grow(halfFaces, -2.0)) flatten(part, coneDegrees, out);
  }
  return out;
}

}  // namespace lo::lightmap_internal
