// The sweep's points (one setting varied at a time from the paper's), their
// labels and cache keys, and the Pareto fronts of error against cost.

#include <cmath>
#include <sstream>

#include "core/error.h"
#include "core/resources.h"
#include "sweep/sweep.h"
#include "sweep/sweep_internal.h"

namespace lo {
namespace sweep_internal {

std::string photonsText(size_t n) {
  if (n >= 1000000 && n % 100000 == 0) {
    std::ostringstream os;
    os << double(n) / 1e6 << "M";
    return os.str();
  }
  if (n >= 1000 && n % 1000 == 0) return std::to_string(n / 1000) + "k";
  return std::to_string(n);
}

double percent2(double fraction) { return std::round(10000.0 * fraction) / 100.0; }

}  // namespace sweep_internal

std::string SweepPoint::label() const {
  using namespace sweep_internal;
  // A target bake's photons and k follow from its target.
  std::string s = "d" + std::to_string(depth) + " " +
                  (targetError > 0 ? "t" + formatNumber(targetError)
                                   : photonsText(photons) + " k" + std::to_string(knn)) +
                  " r" + formatNumber(radiusVoxels) + " v" + vdls;
  if (!interpolation) s += " no-interp";
  if (halfFloat) s += " half";
  if (!cosineCorrection) s += " paper-cosine";
  if (!layers) s += " no-layers";
  if (!occlusion) s += " no-occlusion";
  if (!edgeCorrection) s += " no-edge";
  if (smoothing != BakeParams{}.smoothing) s += smoothing ? " smooth" : " no-smooth";
  if (representation != representationName(LightRepresentation::Vdl)) s += " " + representation;
  if (tolerance > 0) s += " tol" + formatNumber(tolerance);
  return s;
}

std::string SweepPoint::bakeKey() const {
  using namespace sweep_internal;
  return "d" + std::to_string(depth) +
         (targetError > 0 ? "-t" + formatNumber(targetError) : "") + "-p" +
         std::to_string(photons) + "-k" + std::to_string(knn) +
         "-r" + formatNumber(radiusVoxels) + "-v" + vdls + (layers ? "" : "-l0") +
         (occlusion ? "" : "-o0") + (edgeCorrection ? "" : "-e0") +
         (smoothing == BakeParams{}.smoothing ? "" : (smoothing ? "-s1" : "-s0")) +
         (representation == representationName(LightRepresentation::Vdl) ? "" : "-" + representation);
}

std::string SweepPoint::key() const {
  return bakeKey() + (interpolation ? "-i1" : "-i0") + (halfFloat ? "-h1" : "-h0") +
         (cosineCorrection ? "" : "-c0") +
         (tolerance > 0 ? "-t" + formatNumber(tolerance) : "");
}

SweepPoint paperPoint() { return SweepPoint{}; }

std::vector<SweepPoint> sweepPoints(SweepScale scale) {
  std::vector<SweepPoint> points;
  auto add = [&points](SweepPoint p) {
    for (const SweepPoint& q : points)
      if (q.sameSettings(p)) return;
    points.push_back(p);
  };
  auto vary = [&](const char* group, auto setter) {
    SweepPoint p = paperPoint();
    p.group = group;
    setter(p);
    add(p);
  };
  if (scale == SweepScale::Tiny) {
    SweepPoint p;
    p.group = "depth";
    p.photons = 20000;
    p.knn = 20;
    p.depth = 3;
    add(p);
    p.depth = 4;
    add(p);
    p.group = "interpolation";
    p.interpolation = false;
    add(p);
    return points;
  }
  add(paperPoint());
  const bool full = scale == SweepScale::Full;
  const std::vector<int> depths = full ? std::vector<int>{3, 4, 5, 7, 8} : std::vector<int>{4, 5};
  const std::vector<size_t> photons =
      full ? std::vector<size_t>{50000, 150000, 300000, 1200000, 2500000, 5000000}
           : std::vector<size_t>{150000, 300000};
  const std::vector<int> knns =
      full ? std::vector<int>{10, 30, 100, 150, 600, 1000} : std::vector<int>{30, 100};
  const std::vector<float> radii = full ? std::vector<float>{1, 2, 3, 4, 6} : std::vector<float>{};
  const std::vector<std::string> vdls = full ? std::vector<std::string>{"1", "2", "8", "auto"}
                                             : std::vector<std::string>{"1", "auto"};
  for (int d : depths) vary("depth", [d](SweepPoint& p) { p.depth = d; });
  for (size_t n : photons) vary("photons", [n](SweepPoint& p) { p.photons = n; });
  for (int k : knns) vary("knn", [k](SweepPoint& p) { p.knn = k; });
  for (float r : radii) vary("radius", [r](SweepPoint& p) { p.radiusVoxels = r; });
  for (const std::string& v : vdls) vary("vdls", [v](SweepPoint& p) { p.vdls = v; });
  vary("interpolation", [](SweepPoint& p) { p.interpolation = false; });
  vary("texels", [](SweepPoint& p) { p.halfFloat = true; });
  vary("cosine", [](SweepPoint& p) { p.cosineCorrection = false; });
  // The accuracy options (docs/accuracy.md), one off at a time, and all off:
  // the gather as it was before them.
  vary("accuracy", [](SweepPoint& p) { p.layers = false; });
  vary("accuracy", [](SweepPoint& p) { p.occlusion = false; });
  vary("accuracy", [](SweepPoint& p) { p.edgeCorrection = false; });
  vary("accuracy", [](SweepPoint& p) { p.smoothing = !p.smoothing; });
  vary("accuracy", [](SweepPoint& p) {
    p.layers = false;
    p.occlusion = false;
    p.edgeCorrection = false;
    p.smoothing = false;
  });
  // Spherical harmonics beside the VDLs (the paper's future work).
  vary("representation", [](SweepPoint& p) { p.representation = representationName(LightRepresentation::Sh1); });
  vary("representation", [](SweepPoint& p) { p.representation = representationName(LightRepresentation::Sh2); });
  // Adaptive leaves (docs/octree.md): the same bake, coarser leaves where the light agrees.
  for (float t : {0.05f, 0.1f, 0.2f, 0.4f}) vary("tolerance", [t](SweepPoint& p) { p.tolerance = t; });
  // Noise targets (bake --target-error): tighter targets at the default
  // depth, and every depth at the command's default target.
  const std::vector<double> targets =
      full ? std::vector<double>{0.2, 0.1, kDefaultTargetError, 0.05, 0.03}
           : std::vector<double>{0.1, kDefaultTargetError};
  for (double t : targets) vary("target", [t](SweepPoint& p) { p.targetError = t; });
  const std::vector<int> targetDepths = full ? std::vector<int>{5, 7, 8} : std::vector<int>{5};
  for (int d : targetDepths) {
    vary("target", [d](SweepPoint& p) {
      p.targetError = kDefaultTargetError;
      p.depth = d;
    });
  }
  vary("tolerance", [](SweepPoint& p) {
    p.representation = representationName(LightRepresentation::Sh1);
    p.tolerance = 0.1f;
  });
  // Combined points: cheaper photon maps with a matching k (the photon
  // density per voxel falls with the count), coarser and finer grids.
  vary("combined", [](SweepPoint& p) {
    p.photons = 300000;
    p.knn = 150;
  });
  vary("combined", [](SweepPoint& p) {
    p.depth = 5;
    p.photons = 300000;
    p.knn = 300;
  });
  if (full) {
    vary("combined", [](SweepPoint& p) {
      p.photons = 150000;
      p.knn = 100;
      p.vdls = "2";
      p.halfFloat = true;
    });
    vary("combined", [](SweepPoint& p) {
      p.depth = 5;
      p.photons = 1200000;
      p.knn = 600;
    });
    vary("combined", [](SweepPoint& p) {
      p.depth = 7;
      p.photons = 2500000;
      p.knn = 300;
    });
  }
  return points;
}

std::vector<bool> paretoFront(const std::vector<double>& cost, const std::vector<double>& error) {
  LO_CHECK_EQ(cost.size(), error.size());
  std::vector<bool> front(cost.size(), true);
  for (size_t i = 0; i < cost.size(); ++i) {
    for (size_t j = 0; j < cost.size() && front[i]; ++j) {
      const bool noWorse = cost[j] <= cost[i] && error[j] <= error[i];
      const bool better = cost[j] < cost[i] || error[j] < error[i];
      if (j != i && noWorse && better) front[i] = false;
    }
  }
  return front;
}

void markParetoFronts(std::vector<SweepResult>& results) {
  std::vector<double> time, memory, error;
  for (const SweepResult& r : results) {
    time.push_back(r.bakeSeconds);
    memory.push_back(r.gpuBytes);
    error.push_back(r.irradianceBinnedRelRmse);
  }
  std::vector<bool> t = paretoFront(time, error), m = paretoFront(memory, error);
  for (size_t i = 0; i < results.size(); ++i) {
    results[i].paretoTime = t[i];
    results[i].paretoMemory = m[i];
  }
}

SweepParams sweepDefaults(SweepScale scale) {
  SweepParams p;
  p.scale = scale;
  switch (scale) {
    case SweepScale::Full:
      p.width = 160, p.height = 120, p.referenceSpp = 8192, p.frames = 5;
      break;
    case SweepScale::Quick:
      p.width = 96, p.height = 72, p.referenceSpp = 2048, p.frames = 2;
      break;
    case SweepScale::Tiny:
      p.width = 24, p.height = 18, p.referenceSpp = 8, p.frames = 1;
      break;
  }
  return p;
}

}  // namespace lo
