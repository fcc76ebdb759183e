#pragma once
/// @file render/camera_path.h
/// @brief Recorded camera paths for `lightoctree view --camera-path`: a text
/// file of keyframes, sampled with linear interpolation. No GL here.
///
/// File format (UTF-8 text, one keyframe per line, see docs/view.md):
///
///     # comments and blank lines are ignored
///     # t  ex ey ez  tx ty tz  [fov]
///     0    0 1 3     0 1 0     45
///     2.5  1 1 2     0 1 0
///
/// t: seconds, strictly increasing; e: eye, t: target, world space; fov:
/// vertical field of view in degrees, 1 to 179 (a line without it keeps the
/// previous keyframe's; lines before the first fov take the first one given; a
/// path with none uses the viewer's --fov).

#include <istream>
#include <string>
#include <vector>

#include "core/math.h"
#include "render/renderer.h"

namespace lo {

struct CameraKey {
  float time = 0;        ///< seconds from the start of the path
  Vec3 eye{0, 0, 1};     ///< world space
  Vec3 target{0, 0, 0};  ///< world space, != eye
  float fovDegrees = 0;  ///< vertical; 0 = not given (the viewer's default)

  /// The line of the file format (fov omitted when 0); parses back exactly.
  std::string ToString() const;
  /// The pinhole camera of this key; `defaultFovDegrees` when fovDegrees is 0.
  PinholeCamera camera(float defaultFovDegrees) const;
};

struct CameraPath {
  std::vector<CameraKey> keys;  ///< at least one; times strictly increasing

  float startTime() const { return keys.empty() ? 0.0f : keys.front().time; }
  float endTime() const { return keys.empty() ? 0.0f : keys.back().time; }
  float duration() const { return endTime() - startTime(); }

  /// Eye, target and fov at time t, linear between the two keyframes around t;
  /// before the first keyframe the first, after the last the last. Where the
  /// interpolated eye and target meet, the target is moved back onto the line
  /// of sight of the earlier keyframe. @throws InputError on an empty path.
  CameraKey sample(float time) const;
  /// Time of frame `frame` of `frames` spread evenly from start to end (the
  /// first frame at the start, the last at the end; one frame: the start).
  float frameTime(int frame, int frames) const;
};

/// Parses the format above. `name` (a file name) starts every error message,
/// followed by the 1-based line number: "path.txt:3: expected 7 or 8 numbers
/// (t ex ey ez tx ty tz [fov]), got 5". @throws InputError on a malformed
/// line, a time not after the previous one, eye == target, a fov outside
/// 1..179, or no keyframes at all.
CameraPath parseCameraPath(std::istream& in, const std::string& name);

/// Reads and parses a path file. @throws InputError naming the file when it
/// cannot be opened or is malformed.
CameraPath readCameraPath(const std::string& path);

/// Appends `key` as one line to the path file at `path`, creating it with a
/// header comment if it does not exist. The new content is written to a
/// temporary name and renamed, so an interrupted write leaves the old file.
/// @throws IoError when the file cannot be written.
void appendCameraKey(const std::string& path, const CameraKey& key);

}  // namespace lo
