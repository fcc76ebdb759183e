// bench_noise: is the per-voxel noise estimate (LightGridVoxels::noise)
// right? For each scene, two bakes that differ only in their seed (A, B)
// and a reference with 16x the photons (R), all with the same grid and the
// same gather: per lit voxel, the differences A - B and A - R against the
// estimated standard deviations. A calibrated estimate gives differences
// whose median is 0.6745 of their standard deviation (a normal's), so
//   ratio = median(|A - B| / sqrt(sA^2 + sB^2)) / 0.6745
// is 1 when the estimate is right, above 1 when it is too small. The
// relative columns compare the medians themselves: the estimate's median
// relative noise beside the measured relative error's median / 0.6745.
// Writes docs/results/noise.md.

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <vector>

#include "bake/bake.h"
#include "core/file.h"
#include "scene/scene.h"

namespace {

constexpr double kHalfNormalMedian = 0.6744897501960817;

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(v.size() / 2), v.end());
  return v[v.size() / 2];
}

struct Row {
  std::string scene;
  int depth = 0, knn = 0;
  size_t photons = 0, voxels = 0;
  double estimated = 0;   // median relative noise of A
  double measuredRef = 0; // median |A - R| / R / 0.6745
  double ratioPair = 0, ratioRef = 0;
  double seconds = 0;
};

Row measure(const std::string& name, const lo::Scene& scene, int depth, int knn, size_t photons) {
  lo::BakeParams p;
  p.depth = depth;
  p.knn = knn;
  p.photons = photons;
  const auto t0 = std::chrono::steady_clock::now();
  p.seed = 1;
  const lo::VdlGrid a = lo::bake(scene, p).grid;
  p.seed = 2;
  const lo::VdlGrid b = lo::bake(scene, p).grid;
  p.seed = 3;
  p.photons = 16 * photons;
  const lo::VdlGrid r = lo::bake(scene, p).grid;
  Row row;
  row.scene = name;
  row.depth = depth;
  row.knn = knn;
  row.photons = photons;
  std::vector<double> est, measured, zPair, zRef;
  for (size_t v = 0; v < a.size(); ++v) {
    const double ya = lo::luminance(a.irradiance[v]), yb = lo::luminance(b.irradiance[v]),
                 yr = lo::luminance(r.irradiance[v]);
    if (!(ya > 0 && yb > 0 && yr > 0)) continue;
    const double sa = a.noise[v] * ya, sb = b.noise[v] * yb, sr = r.noise[v] * yr;
    if (!(sa > 0 && sb > 0 && sr > 0)) continue;
    est.push_back(a.noise[v]);
    measured.push_back(std::fabs(ya - yr) / yr);
    zPair.push_back(std::fabs(ya - yb) / std::sqrt(sa * sa + sb * sb));
    zRef.push_back(std::fabs(ya - yr) / std::sqrt(sa * sa + sr * sr));
  }
  row.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  row.voxels = est.size();
  row.estimated = median(est);
  row.measuredRef = median(measured) / kHalfNormalMedian;
  row.ratioPair = median(zPair) / kHalfNormalMedian;
  row.ratioRef = median(zRef) / kHalfNormalMedian;
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Noise estimate against measured per-voxel error", "bench_noise"};
  const std::string shared = std::string(LO_SOURCE_DIR) + "/../shared/scenes";
  std::string out = std::string(LO_SOURCE_DIR) + "/docs/results/noise.md";
  size_t photons = 300000;
  std::vector<int> depths{6, 7};
  std::vector<int> knns{300, 100000};
  app.add_option("--out", out, "Markdown table to write")->capture_default_str();
  app.add_option("--photons", photons, "Photons of bakes A and B (R has 16x)")->capture_default_str();
  app.add_option("--depths", depths, "Grid depths")->capture_default_str();
  app.add_option("--knn", knns, "Gather k values (100000: every photon within the radius)")
      ->capture_default_str();
  CLI11_PARSE(app, argc, argv);

  const std::vector<std::pair<std::string, std::string>> scenes = {
      {"Cornell box", shared + "/composed/cornell-box.glb"},
      {"Bunny", shared + "/composed/cornell-bunny.glb"},
      {"Dragon", shared + "/composed/cornell-dragon.glb"},
      {"Viking room (textured OBJ)", shared + "/real/viking-room/viking_room_lit.obj"},
  };
  std::ostringstream md;
  md << "# Noise estimate against measured per-voxel error\n\n"
     << "Written by `build/tools/bench_noise` (" << photons
     << " photons in bakes A and B, 16x in the reference R; the bake's other defaults,\n"
     << "smoothing on). Per lit voxel (layer 0), `ratio` = median(|A - B| / sqrt(sA^2 + sB^2)) /"
     << " 0.6745:\n1 when the estimated standard deviations are right, above 1 when they are too"
     << " small.\n`vs R` uses the reference instead of B (it adds the blur that differs between"
     << " R's smaller\nKNN radius and A's). `estimated` is the median relative noise of A;"
     << " `measured` the median\n|A - R| / R over 0.6745 (a standard deviation's worth).\n\n"
     << "| scene | depth | k | voxels | estimated | measured vs R | ratio A-B | ratio vs R | s |\n"
     << "|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& [name, path] : scenes) {
    const lo::Scene scene = lo::loadScene(path);
    for (int depth : depths) {
      for (int k : knns) {
        const Row r = measure(name, scene, depth, k, photons);
        char line[400];
        std::snprintf(line, sizeof line,
                      "| %s | %d | %d | %zu | %.1f%% | %.1f%% | %.2f | %.2f | %.0f |\n",
                      r.scene.c_str(), r.depth, r.knn, r.voxels, 100 * r.estimated,
                      100 * r.measuredRef, r.ratioPair, r.ratioRef, r.seconds);
        std::fputs(line, stdout);
        std::fflush(stdout);
        md << line;
      }
    }
  }
  lo::writeTextAtomically(out, md.str());
  std::printf("wrote %s\n", out.c_str());
  return 0;
}
