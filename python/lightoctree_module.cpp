// `import lightoctree`: the library's entries for Python (pybind11). Like a
// command of tools/, this only converts arguments, calls one library entry
// and converts the result; docs/python.md shows it in use.
//
// A light grid is a `Grid`: its arrays are NumPy views of the grid's own
// memory (no copy; each keeps the Grid alive), read-only so that the VDL
// sums the file contract demands cannot be broken behind its back.

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <string>

#include "bake/bake.h"
#include "bake/convert.h"
#include "core/error.h"
#include "core/file.h"
#include "core/number_range.h"
#include "core/progress.h"
#include "image/image.h"
#include "octree/gpu_octree.h"
#include "octree/octree_irradiance.h"
#include "render/context.h"
#include "render/render_session.h"
#include "scene/pinhole_camera.h"
#include "scene/scene.h"
#include "vdb/vdb_inspect.h"
#include "vdb/vdb_io.h"

namespace py = pybind11;

namespace lo::python {
namespace {

/// A grid and its metadata, shared by the arrays that view it.
struct Grid {
  VdlGrid grid;
  BakeMetadata meta;
  py::dict stats;  ///< the bake's figures (empty for a grid read from a file)
  /// The lookup's octree, built on the first lookup (a grid never changes).
  std::shared_ptr<const GpuOctree> octree;
  const GpuOctree& lookupOctree() {
    if (!octree) octree = std::make_shared<const GpuOctree>(buildGpuOctree(grid, GpuOctreeParams{}));
    return *octree;
  }
};
using GridPtr = std::shared_ptr<Grid>;

/// A read-only array of `shape` and byte `strides` over `data`, kept alive
/// by `owner`.
template <typename T>
py::array view(const py::object& owner, const T* data, std::vector<size_t> shape,
               std::vector<size_t> strides) {
  py::array a(py::dtype::of<T>(), shape, strides, data, owner);
  py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

py::array vec3s(const py::object& owner, const std::vector<Vec3>& v) {
  return view<float>(owner, &v.data()->x, {v.size(), 3}, {sizeof(Vec3), sizeof(float)});
}

/// The bake's progress to a Python callable (task, done, total), called with
/// the interpreter's lock held (the bake runs without it, on its threads).
class CallbackProgress : public ProgressSink {
 public:
  explicit CallbackProgress(py::object callback) : callback_(std::move(callback)) {}
  void begin(const std::string& task, size_t total) override {
    task_ = task;
    call(0, total);
  }
  void update(size_t done, size_t total) override { call(done, total); }
  void end() override {}

 private:
  void call(size_t done, size_t total) {
    py::gil_scoped_acquire lock;
    callback_(task_, done, total);
  }
  py::object callback_;
  std::string task_;
};

/// The arguments are checked as the command's flags are, by the same ranges
/// (bake/bake.h, core/number_range.h), and named by their Python names; 0 is
/// "not given" for photons and target_error, as their defaults.
GridPtr bakeScene(const std::string& scenePath, int depth, size_t photons, double targetError,
                  uint64_t seed, int knn, const std::string& vdls, bool includeDirect,
                  const std::string& targetLight, const py::object& progress) {
  checkPathText(scenePath, "scene");
  checkNumber(depth, kDepthRange, "depth");
  if (photons != 0) checkNumber(double(photons), kPhotonsRange, "photons");
  if (targetError != 0) checkNumber(targetError, kTargetErrorRange, "target_error");
  checkNumber(knn, kKnnRange, "knn");
  if (targetLight != "seen" && targetLight != "indirect") {
    throw InputError("target_light must be 'seen' or 'indirect', got '" + targetLight + "'");
  }
  Scene scene = loadScene(scenePath);
  BakeParams params;
  params.depth = depth;
  setPhotonBudget(params, photons, targetError);
  params.seed = seed;
  params.knn = knn;
  params.vdls = parseVdlCount(vdls);
  params.includeDirect = includeDirect;
  params.targetSeenLight = targetLight == "seen";
  auto out = std::make_shared<Grid>();
  {
    std::unique_ptr<CallbackProgress> sink;
    if (!progress.is_none()) sink = std::make_unique<CallbackProgress>(progress);
    py::gil_scoped_release unlocked;
    BakeResult r = bake(scene, params, sink.get());
    out->grid = std::move(r.grid);
    out->meta = std::move(r.metadata);
    recordSourceScene(out->meta, scenePath);
    py::gil_scoped_acquire lock;
    out->stats["stored_photons"] = r.stats.storedPhotons;
    out->stats["emitted_paths"] = r.stats.emittedPaths;
    out->stats["noise"] = r.stats.noise.ToString();
    out->stats["passes"] = r.stats.passes.size();
  }
  return out;
}

GridPtr readGrid(const std::string& path) {
  checkPathText(path, "path");
  LoadedVdl loaded = readVdlGrid(path);
  auto out = std::make_shared<Grid>();
  out->grid = std::move(loaded.grid);
  out->meta = std::move(loaded.meta);
  return out;
}

py::dict inspectFile(const std::string& path) {
  checkPathText(path, "path");
  const VdbReport r = inspectVdb(path);
  py::dict d;
  d["path"] = r.path;
  d["kind"] = r.kind;
  d["bytes"] = r.fileBytes;
  d["ok"] = r.ok();
  py::list checks;
  for (const VdbCheck& c : r.checks) {
    py::dict check;
    check["name"] = c.name;
    check["passed"] = c.passed;
    check["detail"] = c.detail;
    checks.append(check);
  }
  d["checks"] = checks;
  py::dict meta;
  for (const auto& [key, value] : r.metadata) meta[py::str(key)] = value;
  d["metadata"] = meta;
  return d;
}

GridPtr convertGrid(const Grid& in, int depth, const std::string& vdls, const std::string& scenePath) {
  if (depth != 0) checkNumber(depth, kDepthRange, "depth");  // 0: the grid's own
  checkPathText(scenePath, "scene");
  ConvertParams params;
  params.depth = depth;
  params.vdls = vdls;
  Scene scene;
  if (!scenePath.empty()) {
    scene = loadScene(scenePath);
    params.scene = &scene;
  }
  ConvertResult r = convertLightGrid(in.grid, in.meta, params, nullptr);
  auto out = std::make_shared<Grid>();
  out->grid = std::move(r.grid);
  out->meta = std::move(r.metadata);
  return out;
}

/// E(p, n) through the CPU copy of the renderer's octree lookup.
py::array_t<float> lookup(Grid& g, py::array_t<float, py::array::c_style | py::array::forcecast> points,
                          py::array_t<float, py::array::c_style | py::array::forcecast> normals) {
  if (points.ndim() != 2 || points.shape(1) != 3 || normals.ndim() != 2 || normals.shape(1) != 3 ||
      normals.shape(0) != points.shape(0)) {
    throw InputError("lookup: points and normals must both be arrays of shape (N, 3)");
  }
  const size_t n = size_t(points.shape(0));
  const GpuOctree& octree = g.lookupOctree();
  py::array_t<float> out({n, size_t(3)});
  const float* p = points.data();
  const float* nn = normals.data();
  float* e = out.mutable_data();
  {
    py::gil_scoped_release unlocked;
    for (size_t i = 0; i < n; ++i) {
      const Vec3 v = octreeIrradiance(octree, Vec3(p[3 * i], p[3 * i + 1], p[3 * i + 2]),
                                      normalize(Vec3(nn[3 * i], nn[3 * i + 1], nn[3 * i + 2])));
      e[3 * i] = v.x;
      e[3 * i + 1] = v.y;
      e[3 * i + 2] = v.z;
    }
  }
  return out;
}

/// The render settings the keywords select: the command line's flags by
/// their Python names, defaults the library's (RenderSettings{}), so that
/// `lightoctree.render` draws what `lightoctree render` draws.
RenderSettings renderSettings(int width, int height, const std::string& mode, const py::kwargs& kw) {
  RenderSettings s;
  s.frame.width = width;
  s.frame.height = height;
  s.frame.mode = parseRenderMode(mode);
  for (const auto& [key, value] : kw) {
    const std::string name = py::str(key);
    if (name == "interpolation") s.frame.interpolation = value.cast<bool>();
    else if (name == "specular") s.frame.specular = value.cast<bool>();
    else if (name == "reflections") s.frame.reflections = value.cast<bool>();
    else if (name == "lighting") s.frame.lighting = parseLighting(value.cast<std::string>());
    else if (name == "supersample") s.frame.supersample = value.cast<int>();
    else if (name == "vdls") s.frame.maxVdls = value.cast<int>();
    else if (name == "area_lights") s.renderer.areaLights = value.cast<bool>();
    else if (name == "emitter_lights") s.renderer.emitterLights = value.cast<int>();
    else if (name == "shadow_map_size") s.renderer.shadowMapSize = value.cast<int>();
    else if (name == "cosine_correction") s.octree.cosineCorrection = value.cast<bool>();
    else if (name == "tolerance") s.octree.tolerance = value.cast<float>();
    else if (name == "free_space_tolerance") s.octree.volumeTolerance = value.cast<float>();
    else if (name == "texels") setTexels(s.octree, value.cast<std::string>());
    else throw InputError("render: unknown setting '" + name + "'");
  }
  s.check();
  return s;
}

/// The scene lit by the grid, drawn by the GL renderer (OSMesa, headless)
/// from the scene's camera through the library's render session: linear
/// RGB, shape (height, width, 3).
py::array_t<float> renderImage(const std::string& scenePath, const Grid& g, int width, int height,
                               const std::string& mode, const py::kwargs& kw) {
  checkPathText(scenePath, "scene");
  const RenderSettings settings = renderSettings(width, height, mode, kw);
  Scene scene = loadScene(scenePath);
  RgbImage image;
  {
    py::gil_scoped_release unlocked;
    GlContextParams contextParams;
    contextParams.backend = GlBackend::OSMesa;
    std::unique_ptr<GlContext> context = createGlContext(contextParams);
    RenderSession session(scene, g.grid, *context, settings);
    // The scene's first camera, else one framing its bounds from the side its
    // surfaces face (as `render`).
    image = session.render(PinholeCamera::ofScene(scene), settings.frame.mode);
  }
  py::array_t<float> out({size_t(height), size_t(width), size_t(3)});
  std::copy(image.rgb.begin(), image.rgb.end(), out.mutable_data());
  return out;
}

/// An EXR (linear) or PNG (sRGB decoded) image as (height, width, 3) floats.
py::array_t<float> readImageFile(const std::string& path) {
  checkPathText(path, "path");
  const RgbImage image = readImage(path);
  py::array_t<float> out({size_t(image.height), size_t(image.width), size_t(3)});
  std::copy(image.rgb.begin(), image.rgb.end(), out.mutable_data());
  return out;
}

}  // namespace

PYBIND11_MODULE(lightoctree, m) {
  m.doc() =
      "Light Octree: photon-mapped global illumination baked into sparse OpenVDB grids of "
      "virtual directional lights (docs/python.md).";
  m.attr("__version__") = LO_VERSION;
  py::register_exception<InputError>(m, "InputError", PyExc_ValueError);
  py::register_exception<IoError>(m, "IoError", PyExc_OSError);

  py::class_<Grid, GridPtr>(m, "Grid", "A light grid: voxels with irradiance and VDLs (or SH).")
      .def_property_readonly("size", [](const Grid& g) { return g.grid.size(); },
                             "Active voxels")
      .def_property_readonly("depth", [](const Grid& g) { return g.grid.frame.depth; })
      .def_property_readonly("voxel_size", [](const Grid& g) { return g.grid.frame.voxelSize; },
                             "Voxel edge, scene units")
      .def_property_readonly("origin", [](const Grid& g) {
        const Vec3d o = g.grid.frame.offset;
        const Vec3 c = g.grid.frame.origin;
        return py::make_tuple(o.x + c.x, o.y + c.y, o.z + c.z);
      }, "World position of voxel (0, 0, 0)'s lower corner")
      .def_property_readonly("max_vdls", [](const Grid& g) { return g.grid.maxVdls; })
      .def_property_readonly("sh_terms", [](const Grid& g) { return g.grid.shTerms; })
      .def_property_readonly("coords", [](py::object self) {
        const auto& c = self.cast<const Grid&>().grid.coords;
        return view<int32_t>(self, &c.data()->x, {c.size(), 3}, {sizeof(Coord), sizeof(int32_t)});
      }, "(N, 3) int32 voxel coordinates")
      .def_property_readonly("positions", [](const Grid& g) {
        py::array_t<double> out({g.grid.size(), size_t(3)});
        double* p = out.mutable_data();
        for (size_t v = 0; v < g.grid.size(); ++v) {
          const Vec3 c = g.grid.frame.voxelCenter(g.grid.coords[v]);
          p[3 * v] = g.grid.frame.offset.x + c.x;
          p[3 * v + 1] = g.grid.frame.offset.y + c.y;
          p[3 * v + 2] = g.grid.frame.offset.z + c.z;
        }
        return out;
      }, "(N, 3) float64 voxel centres, world space (a copy)")
      .def_property_readonly("normals", [](py::object self) { return vec3s(self, self.cast<const Grid&>().grid.normals); },
                             "(N, 3) unit normals")
      .def_property_readonly("irradiance", [](py::object self) { return vec3s(self, self.cast<const Grid&>().grid.irradiance); },
                             "(N, 3) RGB irradiance, W/m^2")
      .def_property_readonly("noise", [](py::object self) {
        const auto& n = self.cast<const Grid&>().grid.noise;
        return view<float>(self, n.data(), {n.size()}, {sizeof(float)});
      }, "(N,) relative standard error of each voxel's estimate")
      .def_property_readonly("vdl_count", [](py::object self) {
        const auto& c = self.cast<const Grid&>().grid.vdlCount;
        return view<uint8_t>(self, c.data(), {c.size()}, {sizeof(uint8_t)});
      }, "(N,) VDLs used per voxel")
      .def_property_readonly("vdl_irradiance", [](py::object self) {
        const VdlGrid& g = self.cast<const Grid&>().grid;
        const size_t k = size_t(g.maxVdls);
        return view<float>(self, &g.vdls.data()->irradiance.x, {g.size(), k, 3},
                           {k * sizeof(Vdl), sizeof(Vdl), sizeof(float)});
      }, "(N, max_vdls, 3) RGB irradiance of each VDL, strongest first")
      .def_property_readonly("vdl_direction", [](py::object self) {
        const VdlGrid& g = self.cast<const Grid&>().grid;
        const size_t k = size_t(g.maxVdls);
        return view<float>(self, &g.vdls.data()->direction.x, {g.size(), k, 3},
                           {k * sizeof(Vdl), sizeof(Vdl), sizeof(float)});
      }, "(N, max_vdls, 3) unit direction of each VDL, towards the light")
      .def_property_readonly("stats", [](const Grid& g) { return g.stats; },
                             "The bake's figures (empty for a grid read from a file)")
      .def("__repr__", [](const Grid& g) {
        return "<lightoctree.Grid: " + std::to_string(g.grid.size()) + " voxels, depth " +
               std::to_string(g.grid.frame.depth) + ", " + std::to_string(g.grid.maxVdls) +
               " VDL slots>";
      });

  m.def("bake", &bakeScene, py::arg("scene"), py::arg("depth") = 6, py::arg("photons") = 0,
        py::arg("target_error") = 0.0, py::arg("seed") = 1, py::arg("knn") = BakeParams{}.knn,
        py::arg("vdls") = "4", py::arg("include_direct") = false, py::arg("target_light") = "seen",
        py::arg("progress") = py::none(),
        "Bakes a scene (.gltf, .glb, .obj) as `lightoctree bake` does: photons until the noise "
        "figure reaches target_error (default 0.07), or a fixed number of photons; target_light "
        "'seen' (the noise of the light a viewer sees) or 'indirect' (of the indirect light). "
        "progress(task, done, total) is called as the bake goes.");
  m.def("read", &readGrid, py::arg("path"), "Reads a .vdb written by bake or convert.");
  m.def(
      "write",
      [](const std::string& path, const Grid& g) {
        checkPathText(path, "path");
        writeVdlGrid(path, g.grid, g.meta);
      },
      py::arg("path"), py::arg("grid"),
      "Writes the grid as a .vdb (atomically; a grid the readers would refuse is not written).");
  m.def("inspect", &inspectFile, py::arg("path"),
        "The checks `lightoctree inspect` runs: {'ok', 'checks': [{'name', 'passed', 'detail'}], ...}.");
  m.def("convert", &convertGrid, py::arg("grid"), py::arg("depth") = 0, py::arg("vdls") = "",
        py::arg("scene") = "",
        "Another depth (a finer one needs the scene) or VDL count, as `lightoctree convert`.");
  m.def("lookup", &lookup, py::arg("grid"), py::arg("points"), py::arg("normals"),
        "Irradiance E(p, n) at world points with unit normals, (N, 3) each: the renderer's "
        "octree lookup on the CPU.");
  m.def("render", &renderImage, py::arg("scene"), py::arg("grid"), py::arg("width") = 400,
        py::arg("height") = 300, py::arg("mode") = "full",
        "The scene lit by the grid from its camera, as `lightoctree render` draws it (OSMesa): "
        "linear RGB, shape (height, width, 3). Keywords as the command's flags, defaults the "
        "same: interpolation, specular, reflections, area_lights, cosine_correction (bool); "
        "lighting ('octree' | 'atlas'), texels ('compact' | 'half' | 'float'); supersample, vdls, "
        "emitter_lights, shadow_map_size (int); tolerance, free_space_tolerance (0..1).");
  m.def("read_image", &readImageFile, py::arg("path"),
        "An image file: EXR as linear floats, PNG decoded from sRGB; shape (height, width, 3).");
}

}  // namespace lo::python
