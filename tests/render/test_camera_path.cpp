// Camera paths (render/camera_path.h) and the walkthrough camera
// (render/fly_camera.h): parsing, errors naming the line, interpolation,
// appending, and the fly camera's frame against PinholeCamera::lookAt.

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "core/error.h"
#include "render/camera_path.h"
#include "render/fly_camera.h"
#include "core/file.h"
#include "test_util.h"

namespace lo {
namespace {

CameraPath parse(const std::string& text) {
  std::istringstream in(text);
  return parseCameraPath(in, "path.txt");
}

/// The message of the InputError that parsing `text` throws ("" if none).
std::string parseError(const std::string& text) {
  try {
    parse(text);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

void expectNear(const Vec3& a, const Vec3& b, float tolerance) {
  EXPECT_NEAR(a.x, b.x, tolerance) << a.ToString() << " vs " << b.ToString();
  EXPECT_NEAR(a.y, b.y, tolerance) << a.ToString() << " vs " << b.ToString();
  EXPECT_NEAR(a.z, b.z, tolerance) << a.ToString() << " vs " << b.ToString();
}

TEST(CameraPath, ParsesKeyframesCommentsAndBlankLines) {
  CameraPath path = parse(
      "# a path\n"
      "\n"
      "0   0 1 3   0 1 0   45   # first\n"
      "  2.5 1 1 2  0 1.5 0\n"
      "4 -1 2 2 0 1 0 60\n");
  ASSERT_EQ(path.keys.size(), 3u);
  EXPECT_EQ(path.keys[0].time, 0.0f);
  EXPECT_EQ(path.keys[0].eye, Vec3(0, 1, 3));
  EXPECT_EQ(path.keys[0].target, Vec3(0, 1, 0));
  EXPECT_EQ(path.keys[0].fovDegrees, 45.0f);
  EXPECT_EQ(path.keys[1].time, 2.5f);
  EXPECT_EQ(path.keys[1].target, Vec3(0, 1.5f, 0));
  EXPECT_EQ(path.keys[1].fovDegrees, 45.0f) << "a line without fov keeps the previous one";
  EXPECT_EQ(path.keys[2].fovDegrees, 60.0f);
  EXPECT_EQ(path.startTime(), 0.0f);
  EXPECT_EQ(path.endTime(), 4.0f);
  EXPECT_EQ(path.duration(), 4.0f);
}

TEST(CameraPath, FovBeforeTheFirstGivenTakesIt) {
  CameraPath path = parse("0 0 0 1 0 0 0\n1 0 0 2 0 0 0\n2 0 0 3 0 0 0 30\n3 0 0 4 0 0 0\n");
  for (const CameraKey& k : path.keys) EXPECT_EQ(k.fovDegrees, 30.0f) << k.ToString();
  CameraPath none = parse("0 0 0 1 0 0 0\n1 0 0 2 0 0 0\n");
  for (const CameraKey& k : none.keys) EXPECT_EQ(k.fovDegrees, 0.0f) << "viewer's default";
  EXPECT_NEAR(none.keys[0].camera(50.0f).yfov, 50.0f * kPi / 180.0f, 1e-6f);
}

TEST(CameraPath, KeyLineRoundTripsExactly) {
  CameraKey k;
  k.time = 1.0f / 3.0f;
  k.eye = Vec3(0.1f, -1e-7f, 12345.678f);
  k.target = Vec3(3.0e-38f, 0.7f, -2.0f / 7.0f);
  k.fovDegrees = 47.123456f;
  CameraPath path = parse(k.ToString() + "\n");
  ASSERT_EQ(path.keys.size(), 1u);
  EXPECT_EQ(path.keys[0].time, k.time);
  EXPECT_EQ(path.keys[0].eye, k.eye);
  EXPECT_EQ(path.keys[0].target, k.target);
  EXPECT_EQ(path.keys[0].fovDegrees, k.fovDegrees);
  k.fovDegrees = 0;
  EXPECT_EQ(parse(k.ToString()).keys[0].fovDegrees, 0.0f) << k.ToString();
}

TEST(CameraPath, ErrorsNameTheFileAndLine) {
  EXPECT_EQ(parseError("0 0 0 1 0 0 0\n\n# c\n1 0 0 1 0 0\n"),
            "path.txt:4: expected 7 or 8 numbers (t ex ey ez tx ty tz [fov]), got 6");
  EXPECT_EQ(parseError("0 0 0 1 0 0 0 45 9\n"),
            "path.txt:1: expected 7 or 8 numbers (t ex ey ez tx ty tz [fov]), got 9");
  EXPECT_EQ(parseError("0 0 0 1 0 0 zero\n"), "path.txt:1: 'zero' is not a number");
  EXPECT_EQ(parseError("0 0 0 1 0 0 0,\n"), "path.txt:1: '0,' is not a number");
  EXPECT_EQ(parseError("0 0 0 nan 0 0 0\n"), "path.txt:1: 'nan' is not a finite float");
  EXPECT_EQ(parseError("0 0 0 1e39 0 0 0\n"), "path.txt:1: '1e39' is not a finite float");
  EXPECT_EQ(parseError("1 0 0 1 0 0 0\n2 0 0 1 0 0 0\n2 0 0 1 0 0 0\n"),
            "path.txt:3: time 2 is not after the previous keyframe's 2 (times must increase)");
  EXPECT_EQ(parseError("1 0 0 1 0 0 0\n0.5 0 0 1 0 0 0\n"),
            "path.txt:2: time 0.5 is not after the previous keyframe's 1 (times must increase)");
  EXPECT_EQ(parseError("0 1 2 3 1 2 3\n"),
            "path.txt:1: eye and target are the same point ([1, 2, 3])");
  EXPECT_EQ(parseError("0 0 0 1 0 0 0 180\n"), "path.txt:1: fov 180 degrees is outside 1..179");
  EXPECT_EQ(parseError("0 0 0 1 0 0 0 0.5\n"), "path.txt:1: fov 0.5 degrees is outside 1..179");
  EXPECT_EQ(parseError("# only a comment\n\n"),
            "path.txt: no keyframes (expected lines 't ex ey ez tx ty tz [fov]')");
  EXPECT_EQ(parseError(""), "path.txt: no keyframes (expected lines 't ex ey ez tx ty tz [fov]')");
  // A NUL byte cut the message at it, and "1\0x" read as 1; bytes of a
  // binary file (a JPEG given as the path) were quoted raw (H10-7-85).
  EXPECT_EQ(parseError(std::string("0 0 0 1 0 0 1\0x\n", 16)),
            "path.txt:1: holds a NUL byte: not a text file of keyframes ('t ex ey ez tx ty tz "
            "[fov]' a line)");
  EXPECT_EQ(parseError("\xff\xd8\xff\xe0 0 0 1 0 0 0\n"), "path.txt:1: '\\xff\\xd8\\xff\\xe0' is not a number");
  EXPECT_EQ(parseError("0 0 0 1 0 0 \x1b[31m\n"), "path.txt:1: '\\x1b[31m' is not a number");
}

TEST(CameraPath, MissingFileIsNamed) {
  std::string missing = test::outputDir("CameraPathMissing") + "/nope.txt";
  try {
    readCameraPath(missing);
    FAIL() << "no exception";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), missing + ": the camera path does not exist");
  }
}

TEST(CameraPath, SamplesLinearlyAndClampsAtTheEnds) {
  CameraPath path = parse(
      "1  0 0 0   0 0 -1  40\n"
      "3  2 0 0   2 0 -1  60\n"
      "4  2 4 0   2 4 -1  60\n");
  CameraKey a = path.sample(2.0f);
  EXPECT_EQ(a.time, 2.0f);
  expectNear(a.eye, Vec3(1, 0, 0), 1e-6f);
  expectNear(a.target, Vec3(1, 0, -1), 1e-6f);
  EXPECT_NEAR(a.fovDegrees, 50.0f, 1e-5f);
  CameraKey b = path.sample(3.25f);
  expectNear(b.eye, Vec3(2, 1, 0), 1e-6f);
  EXPECT_NEAR(b.fovDegrees, 60.0f, 1e-5f);
  // Exactly at keyframes: the keyframe itself.
  for (const CameraKey& k : path.keys) {
    CameraKey s = path.sample(k.time);
    EXPECT_EQ(s.eye, k.eye) << k.ToString();
    EXPECT_EQ(s.target, k.target) << k.ToString();
  }
  // Outside the span: the end keyframes.
  EXPECT_EQ(path.sample(-5.0f).eye, Vec3(0, 0, 0));
  EXPECT_EQ(path.sample(100.0f).eye, Vec3(2, 4, 0));
  EXPECT_EQ(path.sample(std::nanf("")).eye, Vec3(0, 0, 0));
  CameraPath single = parse("7 1 2 3 4 5 6\n");
  EXPECT_EQ(single.sample(0.0f).eye, Vec3(1, 2, 3));
  EXPECT_EQ(single.sample(9.0f).target, Vec3(4, 5, 6));
  EXPECT_THROW(CameraPath().sample(0.0f), InputError);
}

TEST(CameraPath, CrossingEyeAndTargetKeepsALineOfSight) {
  // Halfway, eye and target are both at the origin.
  CameraPath path = parse("0  -1 0 0  1 0 0\n2  1 0 0  -1 0 0\n");
  CameraKey k = path.sample(1.0f);
  expectNear(k.eye, Vec3(0, 0, 0), 1e-6f);
  expectNear(k.target - k.eye, Vec3(2, 0, 0), 1e-6f);
  PinholeCamera c = k.camera(45.0f);
  expectNear(c.forward, Vec3(1, 0, 0), 1e-6f);
}

TEST(CameraPath, FrameTimesSpanThePath) {
  CameraPath path = parse("2 0 0 1 0 0 0\n6 0 0 2 0 0 0\n");
  EXPECT_EQ(path.frameTime(0, 3), 2.0f);
  EXPECT_EQ(path.frameTime(1, 3), 4.0f);
  EXPECT_EQ(path.frameTime(2, 3), 6.0f);
  EXPECT_EQ(path.frameTime(0, 1), 2.0f);
}

TEST(CameraPath, AppendCreatesThenExtendsTheFile) {
  std::string dir = test::outputDir("CameraPathAppend");
  std::string file = dir + "/recorded.txt";
  CameraKey a;
  a.time = 0;
  a.eye = Vec3(1, 2, 3);
  a.target = Vec3(1, 2, 2);
  a.fovDegrees = 45;
  CameraKey b = a;
  b.time = 1.5f;
  b.eye = Vec3(-1, 0.25f, 9);
  appendCameraKey(file, a);
  appendCameraKey(file, b);
  EXPECT_TRUE(leftoverTemporaries(file).empty());
  CameraPath path = readCameraPath(file);
  ASSERT_EQ(path.keys.size(), 2u);
  EXPECT_EQ(path.keys[0].eye, a.eye);
  EXPECT_EQ(path.keys[1].eye, b.eye);
  EXPECT_EQ(path.keys[1].time, 1.5f);
  std::ifstream f(file);
  std::string first;
  std::getline(f, first);
  EXPECT_EQ(first.rfind("# ", 0), 0u) << "a new file starts with a comment: " << first;

  // A file without a final newline gets one before the appended line.
  std::string bare = dir + "/bare.txt";
  std::ofstream(bare) << "0 0 0 1 0 0 0";
  CameraKey c = a;
  c.time = 2;
  appendCameraKey(bare, c);
  EXPECT_EQ(readCameraPath(bare).keys.size(), 2u);
}

TEST(FlyCamera, LookingAtReproducesTheViewDirection) {
  const Vec3 eye(0.5f, 1.0f, 2.0f);
  for (const Vec3& target : {Vec3(0.5f, 1.0f, 0.0f), Vec3(3.0f, 1.0f, 2.0f), Vec3(-2, 0, 5),
                             Vec3(0.5f, -3.0f, 1.9f), Vec3(1, 2, 2)}) {
    FlyCamera fly = FlyCamera::lookingAt(eye, target, 0.7f);
    Vec3 expected = normalize(target - eye);
    expectNear(fly.forward(), expected, 1e-5f);
    // The same frame as PinholeCamera::lookAt (the convention `render` uses).
    PinholeCamera a = fly.camera(), b = PinholeCamera::lookAt(eye, target, 0.7f);
    expectNear(a.forward, b.forward, 1e-5f);
    expectNear(a.up, b.up, 1e-5f);
    EXPECT_EQ(a.eye, eye);
    EXPECT_EQ(a.yfov, 0.7f);
    EXPECT_NEAR(dot(fly.right(), fly.forward()), 0.0f, 1e-6f);
    EXPECT_NEAR(dot(fly.up(), fly.forward()), 0.0f, 1e-6f);
    EXPECT_NEAR(length(fly.up()), 1.0f, 1e-6f);
    EXPECT_GT(fly.up().y, 0.0f) << "never upside down";
  }
}

TEST(FlyCamera, StraightUpIsClampedBelowThePole) {
  FlyCamera fly = FlyCamera::lookingAt(Vec3(0, 0, 0), Vec3(0, 5, 0), 0.7f);
  EXPECT_NEAR(fly.pitch, FlyCamera::kMaxPitch, 1e-6f);
  PinholeCamera c = fly.camera();
  EXPECT_TRUE(isFinite(c.up));
  EXPECT_NEAR(length(c.up), 1.0f, 1e-5f);
  fly.turn(0.0f, 1.0f);
  EXPECT_EQ(fly.pitch, FlyCamera::kMaxPitch);
  fly.turn(0.0f, -10.0f);
  EXPECT_EQ(fly.pitch, -FlyCamera::kMaxPitch);
}

TEST(FlyCamera, MovesSpeedTimesSecondsAlongItsAxes) {
  FlyCamera fly = FlyCamera::lookingAt(Vec3(0, 0, 0), Vec3(1, 0, 0), 0.7f);  // yaw 90 degrees
  fly.speed = 2.0f;
  fly.move(Vec3(0, 0, 1), 0.5f);  // forward
  expectNear(fly.position, Vec3(1, 0, 0), 1e-6f);
  fly.move(Vec3(1, 0, 0), 0.5f);  // right of +X, with +Y up, is +Z
  expectNear(fly.position, Vec3(1, 0, 1), 1e-6f);
  fly.move(Vec3(0, 1, 0), 0.25f);  // world up
  expectNear(fly.position, Vec3(1, 0.5f, 1), 1e-6f);
  // Diagonal (forward + right) covers the same distance as one axis.
  Vec3 before = fly.position;
  fly.move(Vec3(1, 0, 1), 1.0f);
  EXPECT_NEAR(length(fly.position - before), 2.0f, 1e-5f);
  fly.move(Vec3(0, 0, 0), 1.0f);  // no key held: no move, no NaN
  EXPECT_TRUE(isFinite(fly.position));
}

TEST(FlyCamera, TurnWrapsYawAndKeyRoundTripsThroughAPath) {
  FlyCamera fly;
  fly.turn(3.0f * kPi, 0.0f);
  EXPECT_LE(std::fabs(fly.yaw), kPi + 1e-6f);
  expectNear(fly.forward(), Vec3(0, 0, 1), 1e-5f);  // half a turn from -Z

  fly = FlyCamera::lookingAt(Vec3(1, 2, 3), Vec3(-4, 0, 1), 0.9f);
  CameraPath path;
  path.keys.push_back(fly.key(0.0f));
  std::istringstream in(path.keys[0].ToString());
  CameraKey back = parseCameraPath(in, "k").keys[0];
  PinholeCamera c = back.camera(45.0f);
  expectNear(c.eye, fly.position, 1e-6f);
  expectNear(c.forward, fly.forward(), 1e-5f);
  EXPECT_NEAR(c.yfov, 0.9f, 1e-5f);
}

TEST(CameraPath, APipeIsRefusedNotWaitedOn) {
  const std::string fifo = test::outputDir("CameraPath_Pipe") + "/path.txt";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_THROW(readCameraPath(fifo), InputError);
  EXPECT_THROW(appendCameraKey(fifo, CameraKey{}), InputError);
}

}  // namespace
}  // namespace lo
