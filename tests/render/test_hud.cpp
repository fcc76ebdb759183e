// The view window's HUD (render/hud.h): its text is drawn in the top-left
// box and nowhere else, legible (glyph pixels bright on the dark box), and
// the box grows with the lines (H adds the keys).

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "render/context.h"
#include "render/hud.h"
#include "render/viewer.h"
#include "test_util.h"

namespace lo {
namespace {

TEST(Hud, TextLiesInItsBoxInTheTopLeftCorner) {
  if (!test::osmesaContext()) GTEST_SKIP() << "no OSMesa context available";
  HudOverlay hud;
  const std::vector<std::string> lines{"12.3 ms  81 fps   full, interp on, 4 VDLs, EV +0.0",
                                       "octree: no octree yet (tracing photons 40%)", "H: keys"};
  constexpr int kWidth = 640, kHeight = 240;
  const RgbImage image = hud.drawOffscreen(lines, kWidth, kHeight);
  int boxW = 0, boxH = 0;
  HudOverlay::extent(lines, 2.0f, boxW, boxH);
  ASSERT_GT(boxW, 300);
  ASSERT_LT(boxW, kWidth);
  ASSERT_LT(boxH, kHeight);
  int bright = 0, outside = 0;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const float v = image.pixel(x, y)[0];
      const bool inBox = x < boxW && y < boxH;
      if (v > 0.5f) (inBox ? bright : outside) += 1;
    }
  }
  EXPECT_EQ(outside, 0) << "HUD pixels outside its box";
  // Three lines of about 45 glyphs, a few dozen lit pixels each at scale 2.
  EXPECT_GT(bright, 2000);
  // The keys make the box taller.
  std::vector<std::string> withKeys = lines;
  const std::string keys = viewerKeyHelp();
  withKeys.push_back(keys.substr(0, keys.find('\n')));
  withKeys.push_back("H                 these keys on the screen");
  int keysW = 0, keysH = 0;
  HudOverlay::extent(withKeys, 2.0f, keysW, keysH);
  EXPECT_EQ(keysH, boxH + 2 * 20);
}

}  // namespace
}  // namespace lo
