// The sweep's report: the CSV, the Markdown table, gnuplot's data and
// script (gnuplot runs as a program), and the pictures for the docs.

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "core/error.h"
#include "core/file.h"
#include "core/resources.h"
#include "image/compare.h"
#include "image/image.h"
#include "sweep/sweep.h"
#include "sweep/sweep_internal.h"

namespace fs = std::filesystem;

namespace lo {
namespace sweep_internal {
namespace {

/// Runs `gnuplot SCRIPT` with `dir` as its working folder (no shell: the
/// folder and script are arguments), output discarded. False when gnuplot is
/// missing or fails.
bool runGnuplot(const std::string& dir, const std::string& script) {
  std::string quoted;  // gnuplot single-quoted string: '' stands for '
  for (char c : dir) quoted += c == '\'' ? std::string("''") : std::string(1, c);
  const std::string cd = "cd '" + quoted + "'";
  const std::string absolute = fs::absolute(script).string();
  std::vector<char*> argv = {const_cast<char*>("gnuplot"), const_cast<char*>("-e"),
                             const_cast<char*>(cd.c_str()), const_cast<char*>(absolute.c_str()),
                             nullptr};
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 2, "/dev/null", O_WRONLY, 0);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, "gnuplot", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) return false;
  int status = 0;
  if (waitpid(pid, &status, 0) != pid) return false;
  return WIFEXITED(status) && WEXITSTATUS(status) == 0;
}

/// Puts images side by side with a gap of `gap` black pixels.
RgbImage sideBySide(const std::vector<const RgbImage*>& images, int gap) {
  int width = 0, height = 0;
  for (const RgbImage* im : images) {
    width += im->width + (width > 0 ? gap : 0);
    height = std::max(height, im->height);
  }
  RgbImage out(width, height);
  int x0 = 0;
  for (const RgbImage* im : images) {
    for (int y = 0; y < im->height; ++y)
      for (int x = 0; x < im->width; ++x)
        out.set(size_t(y) * size_t(width) + size_t(x0 + x), im->at(size_t(y) * im->width + x));
    x0 += im->width + gap;
  }
  return out;
}

/// PNG exposure that puts the reference's mean luminance near mid grey.
float exposureFor(const RgbImage& reference) {
  double sum = 0;
  size_t n = 0;
  for (size_t i = 0; i < reference.pixelCount(); ++i) {
    const Vec3 v = reference.at(i);
    const double y = 0.2126 * v.x + 0.7152 * v.y + 0.0722 * v.z;
    if (y > 0) {
      sum += y;
      ++n;
    }
  }
  return n && sum > 0 ? float(std::log2(0.3 * double(n) / sum)) : 0.0f;
}

std::string markdownTable(const std::vector<SweepResult>& results) {
  std::ostringstream os;
  os << "| setting | varies | trace s | voxelize s | splat s | gather+cluster s | bake s | "
        "peak RSS MiB | .vdb KiB | GPU KiB | active voxels | GPU leaves | frame ms | "
        "photons | noise figure | irradiance rel. RMSE, 4x4 bins | per pixel | rel. MAE | "
        "indirect image rel. RMSE | front |\n"
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
        "---:|---|\n";
  for (const SweepResult& r : results) {
    const bool paper = r.point.sameSettings(paperPoint());
    char line[1024];
    std::string front = std::string(r.paretoTime ? "T" : "") + (r.paretoMemory ? "M" : "");
    std::snprintf(line, sizeof line,
                  "| %s%s%s | %s | %.2f | %.2f | %.2f | %.2f | %.2f | %.0f | %.0f | %.0f | %.0f "
                  "| %s | %s | %s | %s | %.1f%% | %.1f%% | %.1f%% | %s | %s |\n",
                  paper ? "**" : "", r.point.label().c_str(), paper ? "** (paper)" : "",
                  r.point.group.c_str(), r.traceSeconds, r.voxelizeSeconds, r.splatSeconds,
                  r.clusterSeconds, r.bakeSeconds, r.peakRssBytes / 1048576.0, r.vdbBytes / 1024.0,
                  r.gpuBytes / 1024.0, r.activeVoxels,
                  r.gpuLeaves >= 0 ? formatNumber(r.gpuLeaves).c_str() : "-",
                  r.frameMs >= 0 ? formatNumber(std::round(r.frameMs * 10) / 10).c_str() : "-",
                  formatCount(size_t(r.storedPhotons)).c_str(),
                  r.noiseFigure >= 0
                      ? (formatNumber(std::round(1000 * r.noiseFigure) / 10) + "%").c_str()
                      : "-",
                  100 * r.irradianceBinnedRelRmse, 100 * r.irradianceRelRmse,
                  100 * r.irradianceRelMae,
                  r.indirectRelRmse >= 0
                      ? (formatNumber(std::round(1000 * r.indirectRelRmse) / 10) + "%").c_str()
                      : "-",
                  front.c_str());
    os << line;
  }
  return os.str();
}

/// Data file for gnuplot: x y "label", one point per line, sorted by x.
std::string plotData(std::vector<std::pair<double, std::pair<double, std::string>>> rows) {
  std::sort(rows.begin(), rows.end());
  std::ostringstream os;
  for (const auto& row : rows)
    os << row.first << " " << row.second.first << " \"" << row.second.second << "\"\n";
  return os.str();
}

}  // namespace

void writeSweepPictures(const SweepParams& params, const std::vector<SweepResult>& results,
                        const RgbImage& referenceIrradiance, const RgbImage& emitterMask,
                        const SweepCache& cache) {
  CompareParams compareParams;
  compareParams.ignoreBackground = true;
  compareParams.mask = &emitterMask;
  const float ev = exposureFor(referenceIrradiance);
  auto picture = [&](const SweepResult& r, const std::string& name) {
    const RgbImage octreeImage = readImage(cache.imagePath(r.point, "irradiance"));
    const RgbImage diff = differenceImage(octreeImage, referenceIrradiance, compareParams);
    // The difference image is already display-referred: undo the exposure.
    RgbImage diffScaled = diff;
    for (float& v : diffScaled.rgb) v *= std::exp2(-ev);
    writePng(params.outDir + "/" + name,
             sideBySide({&referenceIrradiance, &octreeImage, &diffScaled}, 4), ev);
  };
  for (const SweepResult& r : results) {
    if (r.point.sameSettings(paperPoint())) picture(r, "irradiance-paper.png");
  }
  const SweepResult* best = nullptr;
  for (const SweepResult& r : results)
    if (r.paretoTime && (!best || r.irradianceBinnedRelRmse < best->irradianceBinnedRelRmse)) best = &r;
  if (best) picture(*best, "irradiance-best.png");
}

}  // namespace sweep_internal

std::string sweepCsv(const std::vector<SweepResult>& results) {
  std::ostringstream os;
  os << "label,group,depth,photons,knn,radius_voxels,vdls,interpolation,half_float,"
        "cosine_correction,trace_s,voxelize_s,splat_s,gather_cluster_s,bake_s,peak_rss_mib,vdb_kib,"
        "gpu_kib,"
        "active_voxels,dense_voxels,vdl_texels,frame_ms,irradiance_rel_rmse,"
        "irradiance_rel_mae,irradiance_binned_rel_rmse,indirect_rel_rmse,stored_photons,"
        "noise_figure,target_error,pareto_time,pareto_memory,paper\n";
  for (const SweepResult& r : results) {
    const SweepPoint& p = r.point;
    char line[1024];
    std::snprintf(
        line, sizeof line,
        "\"%s\",%s,%d,%zu,%d,%g,%s,%d,%d,%d,%.3f,%.3f,%.3f,%.3f,%.3f,%.1f,%.1f,%.1f,%.0f,%.0f,"
        "%.0f,%.2f,%.5f,%.5f,%.5f,%.5f,%.0f,%.5f,%g,%d,%d,%d\n",
        p.label().c_str(), p.group.c_str(), p.depth, p.photons, p.knn, double(p.radiusVoxels),
        p.vdls.c_str(), int(p.interpolation), int(p.halfFloat), int(p.cosineCorrection),
        r.traceSeconds, r.voxelizeSeconds, r.splatSeconds, r.clusterSeconds, r.bakeSeconds,
        r.peakRssBytes / 1048576.0, r.vdbBytes / 1024.0, r.gpuBytes / 1024.0, r.activeVoxels,
        r.denseVoxels, r.vdlTexels, r.frameMs, r.irradianceRelRmse, r.irradianceRelMae,
        r.irradianceBinnedRelRmse, r.indirectRelRmse, r.storedPhotons, r.noiseFigure,
        p.targetError, int(r.paretoTime), int(r.paretoMemory),
        int(p.sameSettings(paperPoint())));
    os << line;
  }
  return os.str();
}

void writeSweepReport(const SweepParams& params, const std::vector<SweepResult>& results,
                      std::FILE* log) {
  using namespace sweep_internal;
  const std::string dir = params.outDir;
  writeTextAtomically(dir + "/sweep.csv", sweepCsv(results));

  // Plot data: x = bake seconds or GPU KiB, y = irradiance relative RMSE in %.
  using Rows = std::vector<std::pair<double, std::pair<double, std::string>>>;
  Rows allTime, allMem, frontTime, frontMem, paperTime, paperMem, toleranceMem;
  for (const SweepResult& r : results) {
    const double e = 100 * r.irradianceBinnedRelRmse, t = r.bakeSeconds, m = r.gpuBytes / 1024.0;
    const std::string l = r.point.label();
    allTime.push_back({t, {e, l}});
    allMem.push_back({m, {e, l}});
    if (r.paretoTime) frontTime.push_back({t, {e, l}});
    if (r.paretoMemory) frontMem.push_back({m, {e, l}});
    if (r.point.sameSettings(paperPoint())) {
      paperTime.push_back({t, {e, l}});
      paperMem.push_back({m, {e, l}});
      toleranceMem.push_back({m, {e, "uniform"}});
    }
    // The adaptive leaves' trade: the paper's bake at each tolerance.
    SweepPoint uniform = r.point;
    uniform.tolerance = 0;
    uniform.group = "paper";
    if (r.point.tolerance > 0 && uniform.sameSettings(paperPoint())) {
      toleranceMem.push_back({m, {e, "tol " + formatNumber(r.point.tolerance)}});
    }
  }
  const std::string dataDir = dir + "/plot-data";
  fs::create_directories(dataDir);
  writeTextAtomically(dataDir + "/all-time.dat", plotData(allTime));
  writeTextAtomically(dataDir + "/all-memory.dat", plotData(allMem));
  writeTextAtomically(dataDir + "/front-time.dat", plotData(frontTime));
  writeTextAtomically(dataDir + "/front-memory.dat", plotData(frontMem));
  writeTextAtomically(dataDir + "/paper-time.dat", plotData(paperTime));
  writeTextAtomically(dataDir + "/paper-memory.dat", plotData(paperMem));
  writeTextAtomically(dataDir + "/tolerance-memory.dat", plotData(toleranceMem));
  const std::string sceneName = fs::path(params.scene).stem().string();
  std::ostringstream gp;
  gp << "# Redraw with: cd " << dir << " && gnuplot sweep.gp\n"
     << "set terminal pngcairo size 1000,700 font 'sans,10'\n"
     << "set logscale x\nset grid\nset key top right\n"
     << "set ylabel 'indirect irradiance: relative RMSE vs reference, 4x4 bins (%)'\n";
  auto plot = [&](const char* png, const char* xlabel, const char* which) {
    const bool memory = std::string(which) == "memory";
    gp << "set output '" << png << "'\n"
       << "set title '" << sceneName << ": error against " << xlabel << "'\n"
       << "set xlabel '" << xlabel << " (log scale)'\n"
       << "plot 'plot-data/all-" << which
       << ".dat' using 1:2 with points pt 7 ps 1 lc rgb '#909090' title 'settings', \\\n"
       << "     'plot-data/front-" << which
       << ".dat' using 1:2 with linespoints pt 7 ps 1.2 lw 2 lc rgb '#d62728' title 'Pareto "
          "front', \\\n"
       << "     'plot-data/front-" << which
       << ".dat' using 1:2:3 with labels offset 1,0.6 left font 'sans,8' notitle, \\\n";
    if (memory) {
      gp << "     'plot-data/tolerance-memory.dat' using 1:2 with linespoints pt 9 ps 1.2 lw 2 "
            "lc rgb '#2ca02c' title 'adaptive leaves (tolerance)', \\\n"
         << "     'plot-data/tolerance-memory.dat' using 1:2:3 with labels offset -1,-0.9 right "
            "font 'sans,8' tc rgb '#2ca02c' notitle, \\\n";
    }
    gp << "     'plot-data/paper-" << which
       << ".dat' using 1:2 with points pt 5 ps 2.2 lc rgb '#1f77b4' title 'paper (d6 600k k300 "
          "v4)'\n";
  };
  plot("error-vs-bake-time.png", "bake time, s", "time");
  plot("error-vs-memory.png", "GPU octree + VDL textures, KiB", "memory");
  writeTextAtomically(dir + "/sweep.gp", gp.str());
  const bool plotted = runGnuplot(dir, dir + "/sweep.gp");
  if (!plotted && log) std::fprintf(log, "sweep: gnuplot failed or missing; no plots drawn\n");

  std::ostringstream md;
  md << "# Sweep: " << sceneName << "\n\n"
     << "Measured by `lightoctree sweep " << fs::path(params.scene).filename().string()
     << (params.scale == SweepScale::Quick ? " --quick" : "") << "`; images " << params.width
     << " x " << params.height << " from the scene camera, references path-traced at "
     << params.referenceSpp
     << " spp. Errors are luminance relative RMSE / MAE over the pixels that see the scene "
        "and no light fixture (`reference --emitter-mask`: there the octree and the path "
        "tracer define irradiance differently), over 4x4-pixel bins and per pixel "
        "(docs/accuracy.md). "
        "*front*: T = on the Pareto front of the binned irradiance error vs bake "
        "time, M = vs GPU bytes. *t0.07*: a target bake (`--target-error 0.07`), whose "
        "photons and k follow from the target; *noise figure*: the bake's own estimate "
        "(docs/accuracy.md, \"How good is a bake\"). Frame times: OSMesa (software GL), "
     << params.frames
     << " frames, indirect mode. Times are wall-clock on this machine "
        "and include every bake stage.\n\n";
  if (params.referenceSpp < 2 || results.empty()) {
    // One sample per pixel has no spread to estimate a standard error from:
    // a floor of 0% was written, never measured (H17-4-2).
    md << "The references' own noise, the floor under these errors, is not known: a standard "
          "error needs two samples per pixel or more (--spp).\n\n";
  } else {
    const SweepResult& first = results.front();
    md << "The references' own noise, the floor under these errors (relative RMS standard "
          "error of luminance, over the same pixels): irradiance "
       << formatNumber(percent2(first.referenceIrradianceNoise)) << "% per pixel, "
       << formatNumber(percent2(first.referenceIrradianceBinnedNoise))
       << "% over the bins; indirect image " << formatNumber(percent2(first.referenceIndirectNoise))
       << "%.\n\n";
  }
  md << markdownTable(results) << "\n";
  if (plotted) {
    md << "![error vs bake time](error-vs-bake-time.png)\n\n"
       << "![error vs memory](error-vs-memory.png)\n\n";
  }
  if (fs::exists(dir + "/irradiance-paper.png"))
    md << "Paper's settings: reference | light octree | difference (red = a quarter of the "
          "mean):\n\n![paper](irradiance-paper.png)\n\n";
  if (fs::exists(dir + "/irradiance-best.png"))
    md << "Most accurate point on the bake-time front:\n\n![best](irradiance-best.png)\n";
  writeTextAtomically(dir + "/sweep.md", md.str());
}

}  // namespace lo
