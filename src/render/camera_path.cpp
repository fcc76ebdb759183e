// Camera paths: parsing, linear interpolation, appending keyframes.

#include "render/camera_path.h"

#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "core/file.h"
#include "core/printable.h"
#include "scene/scene.h"

namespace lo {
namespace {

std::string formatFloat(float v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", double(v));  // 9 digits: a float round-trips
  return buf;
}

std::string formatVec(const Vec3& v) {
  return formatFloat(v.x) + " " + formatFloat(v.y) + " " + formatFloat(v.z);
}

Vec3 lerp(const Vec3& a, const Vec3& b, float u) { return a + (b - a) * u; }

}  // namespace

std::string CameraKey::ToString() const {
  std::string line = formatFloat(time) + "  " + formatVec(eye) + "  " + formatVec(target);
  if (fovDegrees > 0) line += "  " + formatFloat(fovDegrees);
  return line;
}

PinholeCamera CameraKey::camera(float defaultFovDegrees) const {
  float fov = fovDegrees > 0 ? fovDegrees : defaultFovDegrees;
  return PinholeCamera::lookAt(eye, target, fov * kPi / 180.0f);
}

CameraKey CameraPath::sample(float time) const {
  if (keys.empty()) throw InputError("camera path: no keyframes");
  if (!(time > keys.front().time)) return keys.front();  // also NaN
  if (time >= keys.back().time) return keys.back();
  // First key after `time`; keys are few (a hand-recorded path), so linear.
  size_t i = 1;
  while (keys[i].time <= time) ++i;
  const CameraKey& a = keys[i - 1];
  const CameraKey& b = keys[i];
  float u = (time - a.time) / (b.time - a.time);
  CameraKey k;
  k.time = time;
  k.eye = lerp(a.eye, b.eye, u);
  k.target = lerp(a.target, b.target, u);
  if (a.fovDegrees > 0 && b.fovDegrees > 0) {
    k.fovDegrees = a.fovDegrees + (b.fovDegrees - a.fovDegrees) * u;
  } else {
    k.fovDegrees = a.fovDegrees > 0 ? a.fovDegrees : b.fovDegrees;
  }
  // Eye and target interpolate independently and may cross; a camera needs a
  // direction, so keep the earlier key's line of sight there.
  Vec3 aView = a.target - a.eye;
  if (length(k.target - k.eye) <= 1e-6f * std::max(length(aView), 1e-6f)) {
    k.target = k.eye + aView;
  }
  return k;
}

float CameraPath::frameTime(int frame, int frames) const {
  if (frames <= 1) return startTime();
  return startTime() + duration() * float(frame) / float(frames - 1);
}

CameraPath parseCameraPath(std::istream& in, const std::string& name) {
  CameraPath path;
  std::string line;
  int lineNumber = 0;
  int firstFovKey = -1;  // index of the first key that gives a fov
  while (std::getline(in, line)) {
    ++lineNumber;
    std::string where = name + ":" + std::to_string(lineNumber) + ": ";
    // A NUL byte (a binary file given as the path) cut the message short at
    // it, and "1\0x" read as 1 (H10-7-85).
    if (line.find('\0') != std::string::npos) {
      throw InputError(where + "holds a NUL byte: not a text file of keyframes "
                               "('t ex ey ez tx ty tz [fov]' a line)");
    }
    size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream words(line);
    std::vector<float> numbers;
    std::string word;
    while (words >> word) {
      errno = 0;
      char* end = nullptr;
      double v = std::strtod(word.c_str(), &end);
      if (end == word.c_str() || *end != '\0') {
        throw InputError(where + "'" + printable(word) + "' is not a number");
      }
      if (errno == ERANGE || !std::isfinite(v) || std::fabs(v) > 3.0e38) {
        throw InputError(where + "'" + printable(word) + "' is not a finite float");
      }
      numbers.push_back(float(v));
    }
    if (numbers.empty()) continue;
    if (numbers.size() != 7 && numbers.size() != 8) {
      throw InputError(where + "expected 7 or 8 numbers (t ex ey ez tx ty tz [fov]), got " +
                       std::to_string(numbers.size()));
    }
    CameraKey key;
    key.time = numbers[0];
    key.eye = Vec3(numbers[1], numbers[2], numbers[3]);
    key.target = Vec3(numbers[4], numbers[5], numbers[6]);
    if (!path.keys.empty() && !(key.time > path.keys.back().time)) {
      throw InputError(where + "time " + formatFloat(key.time) +
                       " is not after the previous keyframe's " +
                       formatFloat(path.keys.back().time) + " (times must increase)");
    }
    if (key.eye == key.target) {
      throw InputError(where + "eye and target are the same point (" + key.eye.ToString() + ")");
    }
    if (numbers.size() == 8) {
      key.fovDegrees = numbers[7];
      if (!kFovDegreesRange.contains(key.fovDegrees)) {
        throw InputError(where + "fov " + formatFloat(key.fovDegrees) + " degrees is outside " +
                         formatFloat(float(kFovDegreesRange.min)) + ".." +
                         formatFloat(float(kFovDegreesRange.max)));
      }
      if (firstFovKey < 0) firstFovKey = int(path.keys.size());
    } else if (!path.keys.empty()) {
      key.fovDegrees = path.keys.back().fovDegrees;
    }
    path.keys.push_back(key);
  }
  if (in.bad()) throw InputError(name + ": read error");
  if (path.keys.empty()) {
    throw InputError(name + ": no keyframes (expected lines 't ex ey ez tx ty tz [fov]')");
  }
  for (int i = 0; i < firstFovKey; ++i)
    path.keys[size_t(i)].fovDegrees = path.keys[size_t(firstFovKey)].fovDegrees;
  return path;
}

CameraPath readCameraPath(const std::string& path) {
  requireRegularFile(path, "the camera path");
  std::ifstream f(path);
  if (!f) throw InputError(path + ": cannot open the camera path");
  return parseCameraPath(f, path);
}

void appendCameraKey(const std::string& path, const CameraKey& key) {
  std::string old;
  bool exists = std::filesystem::exists(path);
  if (exists) {
    requireRegularFile(path, "the camera path to append to");
    std::ifstream f(path, std::ios::binary);
    if (!f) throw IoError(path + ": cannot read the camera path to append to it");
    std::ostringstream os;
    os << f.rdbuf();
    old = os.str();
    if (!old.empty() && old.back() != '\n') old += '\n';
  } else {
    old =
        "# Light Octree camera path (lightoctree view --camera-path): one keyframe per line\n"
        "# t(seconds)  eye x y z  target x y z  [vertical fov, degrees]\n";
  }
  writeTextAtomically(path, old + key.ToString() + "\n");
}

}  // namespace lo
