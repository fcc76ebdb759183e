#pragma once
/// @file tools/reference_options.h
/// @brief The flags of `reference` and their translation into the path
/// tracer's and the first-hit masks' parameters, as bake_options.h is for
/// `bake`.

#include <cstdint>
#include <string>

#include "camera_options.h"
#include "picture_options.h"
#include "reference/first_hit.h"
#include "reference/path_tracer.h"
#include "scene_options.h"

namespace CLI {
class App;
}

namespace lo::tool {

/// The flags of `reference`, as given.
struct ReferenceOptions : SceneFlags {
  std::string output;
  std::string stdErrorOutput;
  std::string emitterMaskOutput;
  std::string geometryMaskOutput;
  CameraOptions camera;
  int width = 800, height = 600;  // as `render`, so that the images compare pixel for pixel
  int spp = 64;
  double timeBudget = 0;
  std::string part = "full";
  uint64_t seed = 1;
  int threads = 0;
  int maxBounces = 256;
  bool addedOnlyReceive = false;  // --added-only-receive
  PictureOptions picture;         // PNG only, as `render --exposure --tone-map`
  double edgeDistance = 0;        // 0 = one voxel of a depth-6 bake
  std::string json;               // --json FILE: tools/json_report.h
  bool quiet = false;
};

/// The path tracer's parameters for --part full | direct | indirect |
/// irradiance. @throws InputError naming another part.
ReferenceParams referenceParams(const ReferenceOptions& opt);

/// A standard error of one sample per pixel says nothing of the spread: it
/// came out all zeros, which `compare --reference-error` took for no noise.
/// `wanted`: --std-error (Python's std_error). Before the trace
/// (`samplesMade` < 0) --spp decides; after it, the samples a --time-budget
/// allowed. The command and Python share it. @throws InputError when too few.
void checkStdErrorSamples(const ReferenceOptions& opt, bool wanted, int samplesMade = -1);

/// The first hits of --part added-mask | edge-mask: at most 64 rays per
/// pixel, however many --spp asks for.
FirstHitParams firstHitParams(const ReferenceOptions& opt);

/// Registers the description and the flags of `reference` on `cmd`.
void addReferenceOptions(CLI::App* cmd, ReferenceOptions& opt);

}  // namespace lo::tool
