#include <gtest/gtest.h>
#include <sys/resource.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <thread>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <set>
#include <vector>

#include "core/discrete_distribution.h"
#include "core/error.h"
#include "core/math.h"
#include "core/printable.h"
#include "core/progress.h"
#include "core/resources.h"
#include "core/rng.h"

namespace lo {
namespace {

TEST(Rng, SameSeedAndIndexGiveSameStream) {
  Rng a(7, 123), b(7, 123);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(a.next(), b.next());
}

TEST(Rng, NeighbouringIndicesAreDecorrelated) {
  // First outputs of 10,000 consecutive indices: all distinct and uniform in mean.
  std::set<uint32_t> firsts;
  double sum = 0;
  const int n = 10000;
  for (int i = 0; i < n; ++i) {
    Rng r(1, uint64_t(i));
    firsts.insert(r.next());
    sum += Rng(1, uint64_t(i)).uniform();
  }
  EXPECT_EQ(firsts.size(), size_t(n));
  // Mean of n uniforms: standard error 1/sqrt(12 n) ~ 0.0029; allow 5 sigma.
  EXPECT_NEAR(sum / n, 0.5, 5.0 / std::sqrt(12.0 * n));
}

TEST(Rng, UniformStaysInUnitInterval) {
  Rng r(3, 4);
  for (int i = 0; i < 100000; ++i) {
    float u = r.uniform();
    ASSERT_GE(u, 0.0f);
    ASSERT_LT(u, 1.0f);
  }
}

TEST(Math, OrthonormalBasisIsOrthonormalEverywhereIncludingPoles) {
  std::vector<Vec3> normals = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {0, 1, 0},
                               normalize(Vec3{1, 2, 3}), normalize(Vec3{-1e-7f, 0, -1})};
  for (const Vec3& n : normals) {
    Vec3 t, b;
    orthonormalBasis(n, t, b);
    EXPECT_NEAR(length(t), 1.0f, 1e-5f) << n.ToString();
    EXPECT_NEAR(length(b), 1.0f, 1e-5f) << n.ToString();
    EXPECT_NEAR(dot(t, n), 0.0f, 1e-5f) << n.ToString();
    EXPECT_NEAR(dot(b, n), 0.0f, 1e-5f) << n.ToString();
    EXPECT_NEAR(dot(t, b), 0.0f, 1e-5f) << n.ToString();
  }
}

TEST(Math, NormalizeOfZeroIsZeroNotNaN) {
  Vec3 z = normalize(Vec3{0, 0, 0});
  EXPECT_EQ(z, Vec3(0, 0, 0));
}

TEST(Math, BoundsExtendAndEmpty) {
  Bounds3 b;
  EXPECT_TRUE(b.empty());
  b.extend(Vec3{1, 2, 3});
  b.extend(Vec3{-1, 5, 0});
  EXPECT_FALSE(b.empty());
  EXPECT_EQ(b.lower, Vec3(-1, 2, 0));
  EXPECT_EQ(b.upper, Vec3(1, 5, 3));
}

TEST(Check, FailedCheckPrintsBothSides) {
  try {
    LO_CHECK_EQ(2 + 2, 5);
    FAIL() << "LO_CHECK_EQ did not throw";
  } catch (const InternalError& e) {
    std::string msg = e.what();
    EXPECT_NE(msg.find("4 vs 5"), std::string::npos) << msg;
  }
}

class RecordingSink : public ProgressSink {
 public:
  void begin(const std::string&, size_t total) override { total_ = total; began = true; }
  void update(size_t done, size_t) override {
    EXPECT_GE(done, last);
    EXPECT_LE(done, total_);
    last = done;
    ++updates;
  }
  void end() override { ended = true; }
  bool began = false, ended = false;
  size_t last = 0, total_ = 0;
  int updates = 0;
};

TEST(Progress, ReportsMonotonicallyAndFinishesAtTotal) {
  RecordingSink sink;
  {
    Progress p(&sink, "task", 10000);
    for (int i = 0; i < 10000; ++i) p.advance();
  }
  EXPECT_TRUE(sink.began);
  EXPECT_TRUE(sink.ended);
  EXPECT_EQ(sink.last, 10000u);
  // Throttled to about one report per percent.
  EXPECT_LE(sink.updates, 102);
}

TEST(Progress, AStageOfLongStepsReportsAQuarterSecondAfterItsLastReport) {
  // A stage whose percent takes long (a path-traced image of few pixels and
  // many samples: 1% took 38 s) still reports, so that a front end hears
  // Ctrl-C (Python checks for signals at a report; H10-1-118).
  RecordingSink sink;
  Progress p(&sink, "task", 1000000);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  p.advance();
  EXPECT_EQ(sink.updates, 1);
  EXPECT_EQ(sink.last, 1u);
  p.advance();  // neither a new percent nor a quarter second later: no report
  EXPECT_EQ(sink.updates, 1);
  // Work that cannot say how far it got keeps the reports coming: a
  // heartbeat a quarter second on repeats what is done (H12-1-2, H12-5-31).
  p.heartbeat();
  EXPECT_EQ(sink.updates, 1);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  p.heartbeat();
  EXPECT_EQ(sink.updates, 2);
  EXPECT_EQ(sink.last, 1u);  // the report, not the two advances it has not told yet
}


TEST(Resources, MemoryLimitTakesUnitsAndRefusesWhatItCannotRead) {
  // LIGHTOCTREE_MEMORY_LIMIT=2G used to be ignored without a word.
  const size_t unlimited = availableMemoryBytes();
  auto limited = [](const char* value) {
    setenv("LIGHTOCTREE_MEMORY_LIMIT", value, 1);
    const size_t bytes = availableMemoryBytes();
    unsetenv("LIGHTOCTREE_MEMORY_LIMIT");
    return bytes;
  };
  EXPECT_EQ(limited("1048576"), std::min<size_t>(unlimited ? unlimited : SIZE_MAX, 1048576));
  EXPECT_EQ(limited("3M"), size_t(3) << 20);
  EXPECT_EQ(limited("1.5MiB"), size_t(3) << 19);
  EXPECT_EQ(limited("2k"), size_t(2048));
  for (const char* bad : {"2X", "lots", "-5", "0", "2GB and more", "0x100000000", "0x1p32", "inf"}) {
    setenv("LIGHTOCTREE_MEMORY_LIMIT", bad, 1);
    EXPECT_THROW(availableMemoryBytes(), InputError) << bad;
    unsetenv("LIGHTOCTREE_MEMORY_LIMIT");
  }
}


// The one rule by which every stage picks lights: entry k is drawn with
// probability weight(k) / total, zero weights never, and the remapped u is
// uniform in [0, 1] within the drawn entry's stretch.
TEST(DiscreteDistribution, DrawsEachEntryInProportionToItsWeight) {
  DiscreteDistribution d;
  const std::vector<double> weights{0.5, 0.0, 2.0, -1.0, 1.5, 0.0};  // negative counts as 0
  for (double w : weights) d.add(w);
  ASSERT_EQ(d.size(), weights.size());
  EXPECT_DOUBLE_EQ(d.total(), 4.0);
  const int n = 40000;
  std::vector<int> count(weights.size(), 0);
  std::vector<double> remappedSum(weights.size(), 0.0);
  for (int i = 0; i < n; ++i) {
    double remapped = -1;
    const size_t k = d.sample((i + 0.5) / n, &remapped);
    ASSERT_LT(k, weights.size());
    ASSERT_GE(remapped, 0.0);
    ASSERT_LE(remapped, 1.0);
    ++count[k];
    remappedSum[k] += remapped;
  }
  double pmfSum = 0;
  for (size_t k = 0; k < weights.size(); ++k) {
    const double expected = std::max(0.0, weights[k]) / 4.0;
    EXPECT_DOUBLE_EQ(d.pmf(k), expected) << k;
    // Stratified draws: each entry gets its share to within one draw.
    EXPECT_NEAR(count[k], expected * n, 1.0) << k;
    if (count[k] > 0) EXPECT_NEAR(remappedSum[k] / count[k], 0.5, 1e-3) << k;
    pmfSum += d.pmf(k);
  }
  EXPECT_DOUBLE_EQ(pmfSum, 1.0);
  // The ends of [0, 1) land on the first and the last entry of positive weight.
  EXPECT_EQ(d.sample(0.0), 0u);
  EXPECT_EQ(d.sample(std::nextafter(1.0, 0.0)), 4u);
}

}  // namespace
}  // namespace lo

namespace lo {
namespace {

// Issue 43, family 2: under `ulimit -v` the memory checks did not see the
// limit, and the tools died of a bare std::bad_alloc.
TEST(Resources, AvailableMemorySeesTheAddressSpaceLimit) {
  rlimit saved{};
  ASSERT_EQ(getrlimit(RLIMIT_AS, &saved), 0);
  if (saved.rlim_cur == RLIM_INFINITY) EXPECT_EQ(addressSpaceRoomBytes(), SIZE_MAX);
  // What the process maps now, and a limit 256 MiB above it.
  const size_t mapped = mappedBytes();
  ASSERT_GT(mapped, 0u);
  const size_t room = size_t(256) << 20;
  if (saved.rlim_cur != RLIM_INFINITY && saved.rlim_cur < mapped + room) GTEST_SKIP() << "limit already lower";
  rlimit lower = saved;
  lower.rlim_cur = rlim_t(mapped + room);
  ASSERT_EQ(setrlimit(RLIMIT_AS, &lower), 0);
  const size_t seen = addressSpaceRoomBytes();
  const size_t available = availableMemoryBytes();
  ASSERT_EQ(setrlimit(RLIMIT_AS, &saved), 0);
  EXPECT_LE(seen, room);
  EXPECT_GT(seen, room / 2);  // a few pages mapped since, not the whole room
  EXPECT_LE(available, room) << "availableMemoryBytes ignores ulimit -v";
}

// LIGHTOCTREE_MEMORY_LIMIT alone did not stop a run that grew to 24 GB: the
// estimates before the work cannot see all that grows; the watch does.
TEST(Resources, MemoryWatchCallsBackWhenTheProcessGrowsPastItsLimit) {
  const size_t rss = currentRssBytes();
  ASSERT_GT(rss, 0u);
  std::atomic<size_t> seen{0};
  std::atomic<int> calls{0};
  {
    MemoryWatch far(rss + (size_t(8) << 30), [&](size_t) { ++calls; });
    MemoryWatch near(rss + (size_t(32) << 20), [&](size_t now) {
      seen = now;
      ++calls;
    });
    std::vector<char> grown(size_t(96) << 20);
    for (size_t i = 0; i < grown.size(); i += 4096) grown[i] = char(i);
    for (int i = 0; i < 200 && calls.load() == 0; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    volatile char keep = grown[grown.size() / 2];  // the pages stay in use until here
    (void)keep;
  }
  EXPECT_EQ(calls.load(), 1) << "the near limit once, the far one never";
  EXPECT_GT(seen.load(), rss + (size_t(32) << 20));
  // No limit, no watch.
  MemoryWatch none(0, [&](size_t) { ++calls; });
  EXPECT_EQ(calls.load(), 1);
}

// Control characters of a file's strings, escaped before a terminal sees them.
// A quoted name cut to 60 bytes, never inside a UTF-8 character or an
// escape (H16-4-4: a camera named with 100,000 characters made a 100 KB line).
TEST(Printable, AShortFormIsCutWholeCharactersAndEscapes) {
  EXPECT_EQ(printableShort("hall"), "hall");
  EXPECT_EQ(printableShort(std::string(60, 'a')), std::string(60, 'a'));
  EXPECT_EQ(printableShort(std::string(100000, 'a')), std::string(57, 'a') + "...");
  // 56 bytes, then a 2-byte character across the cut at 57.
  const std::string accented = printableShort(std::string(56, 'a') + "\xc3\xa9\xc3\xa9tage");
  EXPECT_EQ(accented, std::string(56, 'a') + "...");
  // An escape across the cut goes whole.
  const std::string escaped = printableShort(std::string(55, 'a') + "\x1b" + std::string(10, 'b'));
  EXPECT_EQ(escaped, std::string(55, 'a') + "...");
  EXPECT_LE(printableShort(std::string(1000, '\x01')).size(), 60u);
}

TEST(Printable, EscapesControlCharactersAndKeepsTheRest) {
  // Well-formed UTF-8 kept; a byte of no UTF-8 character (a Latin-1 é, a
  // UTF-16 file's byte-order mark, a cut or overlong sequence) escaped.
  EXPECT_EQ(printable("plain \xc3\xa9t\xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80"),
            "plain \xc3\xa9t\xc3\xa9 \xe2\x82\xac \xf0\x9f\x98\x80");
  EXPECT_EQ(printable("caf\xe9 \xff\xfe{"), "caf\\xe9 \\xff\\xfe{");
  EXPECT_EQ(printable("\xe2\x82 \xc0\xaf \xed\xa0\x80"),
            "\\xe2\\x82 \\xc0\\xaf \\xed\\xa0\\x80");
  EXPECT_EQ(printable(std::string("a\0b\tc\x7f", 6)), "a\\x00b\\x09c\\x7f");
  EXPECT_EQ(printable("one\ntwo"), "one\\x0atwo");
  EXPECT_EQ(printable("one\ntwo", true), "one\ntwo");
  EXPECT_EQ(printable("\xc2\x85\xc2\xa0"), "\\u0085\xc2\xa0");  // NEL escaped, NBSP kept
  EXPECT_EQ(printable(printable("\x1b[0m")), printable("\x1b[0m"));
}

}  // namespace
}  // namespace lo
