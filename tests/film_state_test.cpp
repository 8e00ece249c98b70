// Exact film sums, film state files, slices and merging, and the renderers' passes, stops and
// continuations: a render split in any way sums to the bits of one render.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cfloat>
#include <cmath>
#include <numeric>
#include <random>
#include <string>
#include <vector>

#include "cpu/integrator.h"
#include "image/exact_sum.h"
#include "image/film_state.h"
#include "render/prepare.h"
#include "render_compare.h"
#include "scene/load_scene.h"
#include "scene/scene.h"
#include "test_util.h"
#include "vulkan/backend.h"

namespace pt {
namespace {

using test::kConfigs;

SceneData prepareConfig(const std::string& config, int size) {
  return prepareScene(loadScene(kConfigs / config), RenderSettings{.width = size, .height = size});
}

// Exact equality of two films: sums (every limb), counts.
void expectSameFilm(const Film& a, const Film& b) {
  ASSERT_EQ(a.width, b.width);
  ASSERT_EQ(a.height, b.height);
  for (size_t i = 0; i < a.pixelCount(); ++i) {
    ASSERT_EQ(a.exact[i], b.exact[i]) << "pixel " << i;
    ASSERT_EQ(a.sum(i), b.sum(i)) << "pixel " << i;
    ASSERT_EQ(a.sampleCount[i], b.sampleCount[i]) << "pixel " << i;
    ASSERT_EQ(a.invalidCount[i], b.invalidCount[i]) << "pixel " << i;
  }
}

// Floats over the whole range: tiny and huge exponents, both signs, denormals.
std::vector<float> wideFloats(size_t n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<uint32_t> bits;
  std::vector<float> v;
  while (v.size() < n) {
    const float f = std::bit_cast<float>(bits(rng));
    if (std::isfinite(f)) v.push_back(f);
  }
  v.push_back(FLT_MAX);
  v.push_back(-FLT_MAX);
  v.push_back(std::numeric_limits<float>::denorm_min());
  v.push_back(-0.0f);
  return v;
}

// ---- ExactSum -------------------------------------------------------------------------------

TEST(ExactSum, DoesNotDependOnTheOrderOfAdditions) {
  std::vector<float> v = wideFloats(5000, 1);
  ExactSum forward;
  for (float f : v) forward.add(f);
  std::mt19937 rng(2);
  for (int round = 0; round < 5; ++round) {
    std::shuffle(v.begin(), v.end(), rng);
    ExactSum shuffled;
    for (float f : v) shuffled.add(f);
    EXPECT_EQ(shuffled, forward);
    // In two halves summed separately, then combined, either way round.
    ExactSum a, b;
    for (size_t i = 0; i < v.size(); ++i) (i < v.size() / 3 ? a : b).add(v[i]);
    ExactSum ab = a, ba = b;
    ab.add(b);
    ba.add(a);
    EXPECT_EQ(ab, forward);
    EXPECT_EQ(ba, forward);
  }
  // Adding every value's negation cancels exactly.
  for (float f : v) forward.add(-f);
  EXPECT_EQ(forward, ExactSum{});
  EXPECT_EQ(forward.toDouble(), 0.0);
}

TEST(ExactSum, RoundsOnceToTheNearestDouble) {
  auto sum = [](std::initializer_list<float> values) {
    ExactSum s;
    for (float f : values) s.add(f);
    return s.toDouble();
  };
  EXPECT_EQ(sum({}), 0.0);
  EXPECT_EQ(sum({1.5f, 2.25f}), 3.75);
  EXPECT_EQ(sum({-1.5f, 0.25f}), -1.25);
  EXPECT_EQ(sum({std::numeric_limits<float>::denorm_min()}), std::ldexp(1.0, -149));
  EXPECT_EQ(sum({FLT_MAX, FLT_MAX}), 2.0 * double(FLT_MAX));
  // 1 + 2^-53 is halfway between two doubles: ties go to even (1.0); anything more, however
  // small, rounds up. A double accumulator gets the second wrong in this order.
  const float half = std::ldexp(1.0f, -53), tiny = std::ldexp(1.0f, -100);
  EXPECT_EQ(sum({1.0f, half}), 1.0);
  EXPECT_EQ(sum({1.0f, half, tiny}), 1.0 + std::ldexp(1.0, -52));
  EXPECT_EQ(sum({-1.0f, -half, -tiny}), -(1.0 + std::ldexp(1.0, -52)));
  EXPECT_EQ(double(1.0f) + double(half) + double(tiny), 1.0);
  // Huge and tiny cancel to the tiny one.
  EXPECT_EQ(sum({1e30f, tiny, -1e30f}), double(tiny));
}

TEST(ExactSum, MatchesAPlainDoubleSumWhenThatIsExact) {
  // Multiples of 2^-20 below 2^10 sum exactly in double: the two must agree bit for bit.
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> k(-(1 << 30), 1 << 30);
  ExactSum s;
  double d = 0.0;
  for (int i = 0; i < 100000; ++i) {
    const float f = std::ldexp(float(k(rng) >> 7), -20);
    s.add(f);
    d += double(f);
  }
  EXPECT_EQ(s.toDouble(), d);
}

// ---- Film -----------------------------------------------------------------------------------

TEST(Film, MergesToTheSameBitsInAnyOrder) {
  // Four films of random samples (NaN among them), merged in all 24 orders.
  std::vector<Film> parts(4, Film(3, 2));
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> u(0.0f, 10.0f);
  Film all(3, 2);
  for (int s = 0; s < 400; ++s) {
    for (int p = 0; p < 6; ++p) {
      glm::vec3 v(u(rng) * u(rng), u(rng) / 1e5f, u(rng) * 1e6f);
      if (s == 7 && p == 2) v.x = NAN;
      parts[size_t(s % 4)].add(p % 3, p / 3, v);
      all.add(p % 3, p / 3, v);
    }
  }
  std::vector<int> order{0, 1, 2, 3};
  do {
    Film merged(3, 2);
    for (int i : order) merged.merge(parts[size_t(i)]);
    expectSameFilm(merged, all);
  } while (std::next_permutation(order.begin(), order.end()));
  EXPECT_EQ(all.totalInvalid(), 1u);
}

TEST(Film, TakingSamplesBackRestoresItsBits) {
  Film film(2, 2), before(2, 2);
  const std::vector<float> wide = wideFloats(300, 7);
  for (size_t i = 0; i < 100; ++i) {
    const glm::vec3 v(wide[i], wide[i + 100], wide[i + 200]);
    film.add(int(i % 2), 0, v);
    before.add(int(i % 2), 0, v);
  }
  std::vector<glm::vec3> pass;
  for (size_t i = 0; i < 60; ++i) {
    pass.emplace_back(wide[i + 3], i % 7 == 0 ? NAN : wide[i + 5], wide[i]);
    film.add(int(i % 2), int(i % 3 == 0), pass.back());
  }
  for (size_t i = 0; i < pass.size(); ++i) film.takeBack(int(i % 2), int(i % 3 == 0), pass[i]);
  expectSameFilm(film, before);
}

// ---- Slices ---------------------------------------------------------------------------------

TEST(Slices, CoverTheJobOnceAndStartOnBatchBoundaries) {
  for (const SampleRange job : {SampleRange{0, 64}, SampleRange{0, 1000}, SampleRange{5, 77}}) {
    for (int count : {1, 2, 3, 4, 7}) {
      for (uint32_t unit : {1u, 16u}) {
        uint32_t at = job.first;
        for (int i = 0; i < count; ++i) {
          const SampleRange s = taskSlice(job, i, count, unit);
          EXPECT_EQ(s.first, at);
          EXPECT_LE(s.first, s.end);
          if (s.first > job.first && s.first < job.end) EXPECT_EQ(s.first % unit, 0u);
          at = s.end;
        }
        EXPECT_EQ(at, job.end);
      }
    }
  }
  EXPECT_EQ(taskSlice(SampleRange{0, 64}, 1, 4, 16), (SampleRange{16, 32}));
  EXPECT_EQ(taskSlice(SampleRange{0, 10}, 3, 4, 1), (SampleRange{7, 10}));
}

TEST(Slices, MissingRangesAreNamed) {
  const std::vector<SampleRange> have{{0, 16}, {32, 40}, {48, 64}};
  EXPECT_EQ(missingRanges(have, SampleRange{0, 64}),
            (std::vector<SampleRange>{{16, 32}, {40, 48}}));
  EXPECT_EQ(missingRanges(have, SampleRange{0, 80}),
            (std::vector<SampleRange>{{16, 32}, {40, 48}, {64, 80}}));
  EXPECT_EQ(missingRanges({}, SampleRange{8, 9}), (std::vector<SampleRange>{{8, 9}}));
  EXPECT_TRUE(missingRanges({{0, 64}}, SampleRange{0, 64}).empty());
  EXPECT_EQ((SampleRange{16, 48}).toString(), "16:32");
}

// ---- Film state files -----------------------------------------------------------------------

FilmState sampleState(bool withOpenBatch) {
  FilmState state;
  state.settings = {{"backend", "cpu"}, {"seed", "7"}, {"scene", "0123456789abcdef"}};
  state.info = {{"scene", "configs/x.json"}, {"task", "1/4"}};
  state.film = Film(5, 3);
  std::mt19937 rng(5);
  const std::vector<float> wide = wideFloats(200, 6);
  for (int s = 0; s < 12; ++s) {
    for (int y = 0; y < 3; ++y) {
      for (int x = 0; x < 5; ++x) {
        const float f = wide[size_t(rng() % wide.size())];
        state.film.add(x, y, (s + x) % 9 == 0 ? glm::vec3(INFINITY) : glm::vec3(f, 0.5f, -f));
      }
    }
  }
  state.ranges = {SampleRange{16, 28}};
  if (withOpenBatch) {
    state.ranges = {SampleRange{16, 31}};
    state.open.first = 28;
    state.open.count = 3;
    state.open.sum.assign(15, glm::vec3(0.25f, 1e-30f, 3e30f));
    state.open.invalid.assign(15, 1);
  }
  return state;
}

TEST(FilmStateFile, RoundTripsExactly) {
  test::TempDir dir;
  for (bool open : {false, true}) {
    const FilmState state = sampleState(open);
    writeFilmState(state, dir / "s.ptstate");
    const FilmState back = readFilmState(dir / "s.ptstate");
    EXPECT_EQ(back.settings, state.settings);
    EXPECT_EQ(back.info, state.info);
    EXPECT_EQ(back.ranges, state.ranges);
    expectSameFilm(back.film, state.film);
    EXPECT_EQ(back.open.first, state.open.first);
    EXPECT_EQ(back.open.count, state.open.count);
    EXPECT_EQ(back.open.sum, state.open.sum);
    EXPECT_EQ(back.open.invalid, state.open.invalid);
    expectSameFilm(back.combinedFilm(), state.combinedFilm());
    EXPECT_EQ(back.samplesPerPixel(), open ? 15u : 12u);
  }
  // The header is text a person can read.
  const std::string text = test::readFile(dir / "s.ptstate");
  EXPECT_EQ(text.rfind("pt film state 1\nwidth 5\nheight 3\nsamples 16:15\nopen 28:3\n", 0), 0u)
      << text.substr(0, 80);
  EXPECT_EQ(dir.listing(), std::vector<std::string>{"s.ptstate"});
}

// Every way of breaking a state file gives one InputError naming the file, never a crash or
// a state that reads.
TEST(FilmStateFile, RefusesTruncatedCorruptAndForeignFiles) {
  test::TempDir dir;
  writeFilmState(sampleState(true), dir / "good.ptstate");
  const std::string good = test::readFile(dir / "good.ptstate");
  auto expectRefused = [&](const std::string& bytes, const std::string& why) {
    const auto path = dir.write("bad.ptstate", bytes);
    try {
      readFilmState(path);
      ADD_FAILURE() << "read a broken state: " << why;
    } catch (const InputError& e) {
      const std::string message = e.what();
      EXPECT_EQ(message.rfind(path.string() + ": ", 0), 0u) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  };
  // Every truncation in the header, then every third one.
  const size_t headerEnd = good.find("\ndata ") + 8;
  for (size_t n = 0; n < good.size(); n += n < headerEnd ? 1 : 3) {
    expectRefused(good.substr(0, n), "truncated to " + std::to_string(n));
  }
  // A bit changed in every byte of the header, then in every third byte.
  for (size_t i = 0; i < good.size(); i += i < headerEnd ? 1 : 3) {
    std::string bad = good;
    bad[i] = char(bad[i] ^ (1 << (i % 8)));
    expectRefused(bad, "byte " + std::to_string(i) + " flipped");
  }
  expectRefused(good + "x", "a byte appended");
  // The messages say what is wrong.
  auto messageFor = [&](const std::string& bytes) {
    try {
      readFilmState(dir.write("bad.ptstate", bytes));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("(read)");
  };
  EXPECT_NE(messageFor(good.substr(0, good.size() - 100)).find("truncated"), std::string::npos);
  std::string flipped = good;
  flipped[good.size() - 50] ^= 1;
  EXPECT_NE(messageFor(flipped).find("checksum"), std::string::npos);
  EXPECT_NE(messageFor("P6\n1 1\n255\nabc").find("not a pt film state"), std::string::npos);
  std::string future = good;
  future[14] = '9';
  EXPECT_NE(messageFor(future).find("version 9"), std::string::npos);
  try {
    readFilmState(dir / "none.ptstate");
    ADD_FAILURE();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not found"), std::string::npos);
  }
}

// A photon-mapping render's state: the film holds its estimate (one sample a pixel) after the
// iterations of its one range from 0, and every pixel's state.
FilmState sppmState() {
  FilmState state;
  state.settings = {{"backend", "cpu"}, {"integrator", "sppm"}};
  state.film = Film(5, 3);
  state.ranges = {SampleRange{0, 6}};
  for (int i = 0; i < 15; ++i) {
    state.film.add(i % 5, i / 5, glm::vec3(float(i), 0.5f, 1e-20f));
    state.sppm.push_back(SppmPixelRecord{0.5f / float(i + 1), float(i) * 1.5f,
                                         glm::vec3(1e30f, float(i), 0.0f),
                                         glm::vec3(-0.0f, 3.0f, float(i) / 7.0f), i % 4 == 0});
  }
  return state;
}

// `bytes` (a state file less its checksum) with the checksum a writer would give it.
std::string withChecksum(const std::string& bytes) {
  const uint64_t sum = hashBytes(bytes.data(), bytes.size());
  std::string out = bytes;
  for (int b = 0; b < 8; ++b) out.push_back(char(sum >> (8 * b)));
  return out;
}

TEST(FilmStateFile, SppmStateRoundTripsAndIsChecked) {
  test::TempDir dir;
  const FilmState state = sppmState();
  writeFilmState(state, dir / "s.ptstate");
  const FilmState back = readFilmState(dir / "s.ptstate");
  EXPECT_EQ(back.sppm, state.sppm);
  EXPECT_EQ(back.ranges, state.ranges);
  expectSameFilm(back.film, state.film);
  const std::string good = test::readFile(dir / "s.ptstate");
  EXPECT_NE(good.find("\nsppm 33\ndata "), std::string::npos);
  const std::string body = good.substr(0, good.size() - 8);
  auto messageFor = [&](const std::string& bytes) {
    try {
      readFilmState(dir.write("bad.ptstate", bytes));
    } catch (const InputError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos);
      return std::string(e.what());
    }
    return std::string("(read)");
  };
  // The last pixel's invalid flag, 2 rather than 0 or 1.
  std::string flag = body;
  flag.back() = 2;
  EXPECT_NE(messageFor(withChecksum(flag)).find("invalid flag"), std::string::npos);
  // Iterations that do not start at 0, another record size, a record missing.
  std::string from3 = body;
  from3.replace(from3.find("samples 0:6"), 11, "samples 3:3");
  EXPECT_NE(messageFor(withChecksum(from3)).find("an sppm state of samples 3:3"),
            std::string::npos);
  std::string size = body;
  size.replace(size.find("sppm 33"), 7, "sppm 34");
  EXPECT_NE(messageFor(withChecksum(size)).find("sppm state of 34 bytes per pixel"),
            std::string::npos);
  std::string shorter = body.substr(0, body.size() - 33);
  const size_t data = shorter.find("\ndata ") + 6;
  const size_t eol = shorter.find('\n', data);
  const uint64_t length = std::stoull(shorter.substr(data, eol - data));
  shorter.replace(data, eol - data, std::to_string(length - 33));
  EXPECT_NE(messageFor(withChecksum(shorter)).find("ends early"), std::string::npos);
  // Its states are not merged: slices of its iterations do not add up.
  try {
    mergeFilmStates({NamedFilmState{dir / "s.ptstate", readFilmState(dir / "s.ptstate")}});
    ADD_FAILURE() << "merged an sppm state";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("s.ptstate: holds an sppm render"), std::string::npos)
        << e.what();
  }
}

// ---- Merging states -------------------------------------------------------------------------

TEST(MergeFilmStates, RefusesOtherSettingsSizesAndOverlaps) {
  auto state = [](uint32_t first, uint32_t end, const std::string& seed, int width = 2) {
    FilmState s;
    s.settings = {{"backend", "cpu"}, {"seed", seed}};
    s.film = Film(width, 1);
    s.ranges = {SampleRange{first, end}};
    for (uint32_t i = first; i < end; ++i) {
      for (int x = 0; x < width; ++x) s.film.add(x, 0, glm::vec3(float(i)));
    }
    return s;
  };
  auto message = [](std::vector<NamedFilmState> states) {
    try {
      mergeFilmStates(std::move(states));
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("(merged)");
  };
  EXPECT_EQ(message({{"a", state(0, 4, "1")}, {"b", state(4, 8, "2")}}),
            "b: rendered with other settings than a: seed 2 vs 1");
  EXPECT_EQ(message({{"a", state(0, 4, "1")}, {"b", state(4, 8, "1", 3)}}), "b: is 3x1, a is 2x1");
  // Named the same way whichever order they come in.
  for (bool swap : {false, true}) {
    std::vector<NamedFilmState> states{{"a", state(0, 4, "1")}, {"b", state(2, 8, "1")}};
    if (swap) std::swap(states[0], states[1]);
    EXPECT_EQ(message(std::move(states)),
              "a (samples 0:4) and b (samples 2:6) overlap in samples 2:2");
  }
  // Adjacent and apart: merged, ranges joined where they touch, info kept where shared.
  std::vector<NamedFilmState> states{
      {"c", state(10, 12, "1")}, {"a", state(0, 4, "1")}, {"b", state(4, 8, "1")}};
  states[0].state.info = {{"job", "0:12"}, {"task", "2/3"}};
  states[1].state.info = {{"job", "0:12"}, {"task", "0/3"}};
  states[2].state.info = {{"job", "0:12"}, {"task", "1/3"}};
  const FilmState merged = mergeFilmStates(states);
  EXPECT_EQ(merged.ranges, (std::vector<SampleRange>{{0, 8}, {10, 12}}));
  EXPECT_EQ(merged.info, (KeyValues{{"job", "0:12"}}));
  EXPECT_EQ(merged.film.sampleCount[1], 10u);
  EXPECT_EQ(merged.film.sum(1).x, 0 + 1 + 2 + 3 + 4 + 5 + 6 + 7 + 10 + 11);

  // Open batches: folded in the middle, kept open at the end of the merged samples.
  auto withOpen = [&](uint32_t first, uint32_t end, uint32_t openFirst) {
    FilmState st = state(first, openFirst, "1");
    st.ranges = {SampleRange{first, end}};
    st.open.first = openFirst;
    st.open.count = end - openFirst;
    st.open.sum.assign(2, glm::vec3(100.0f));
    st.open.invalid.assign(2, 0);
    return st;
  };
  const FilmState ends = mergeFilmStates({{"b", withOpen(8, 12, 10)}, {"a", withOpen(0, 8, 6)}});
  EXPECT_EQ(ends.ranges, (std::vector<SampleRange>{{0, 12}}));
  EXPECT_EQ(ends.open.first, 10u);
  EXPECT_EQ(ends.open.count, 2u);
  EXPECT_EQ(ends.film.sampleCount[0], 10u);
  EXPECT_EQ(ends.film.sum(0).x, 0 + 1 + 2 + 3 + 4 + 5 + 100 + 8 + 9);
  EXPECT_EQ(ends.combinedFilm().sum(0).x, 0 + 1 + 2 + 3 + 4 + 5 + 100 + 8 + 9 + 100);
}

// ---- The CPU renderer's passes --------------------------------------------------------------

TEST(CpuPasses, TheImageDoesNotDependOnTheThreadCount) {
  const SceneData data = prepareConfig("cornell-box.json", 24);
  Film one(24, 24);
  renderCpu(data, test::cpuOptions(1, 6), one);
  for (int threads : {2, 3, 5}) {
    Film many(24, 24);
    renderCpu(data, test::cpuOptions(threads, 6), many);
    SCOPED_TRACE(threads);
    expectSameFilm(many, one);
  }
}

TEST(CpuPasses, RunsSplitAnyWaySumToTheBitsOfOneRun) {
  const SceneData data = prepareConfig("cornell-mirror.json", 20);
  Film whole(20, 20);
  renderCpu(data, test::cpuOptions(2, 12), whole);
  // Continued in three calls into one film, as a resumed render does.
  Film continued(20, 20);
  for (auto [first, count] : {std::pair{0, 5}, std::pair{5, 1}, std::pair{6, 6}}) {
    CpuRenderOptions options = test::cpuOptions(2, count);
    options.firstSample = uint32_t(first);
    renderCpu(data, options, continued);
  }
  expectSameFilm(continued, whole);
  // In slices rendered apart and merged in reverse, as `pt merge` does.
  Film merged(20, 20);
  for (auto [first, count] : {std::pair{9, 3}, std::pair{4, 5}, std::pair{0, 4}}) {
    Film slice(20, 20);
    CpuRenderOptions options = test::cpuOptions(1, count);
    options.firstSample = uint32_t(first);
    renderCpu(data, options, slice);
    merged.merge(slice);
  }
  expectSameFilm(merged, whole);
}

TEST(CpuPasses, AStopLeavesWholePassesAndCheckpointsSeeThem) {
  const SceneData data = prepareConfig("cornell-box.json", 32);
  std::atomic<bool> stop{false};
  Film film(32, 32);
  CpuRenderOptions options = test::cpuOptions(2, 1000);
  options.stop = &stop;
  std::vector<int> seen;
  options.checkpoint = [&](int done) {
    seen.push_back(done);
    // The film holds exactly `done` samples per pixel at every checkpoint.
    EXPECT_EQ(film.sampleCount[0] + film.invalidCount[0], uint64_t(done));
    if (done == 3) stop = true;
  };
  const CpuRenderStats stats = renderCpu(data, options, film);
  EXPECT_TRUE(stats.stopped);
  EXPECT_EQ(stats.samplesDone, 3);
  EXPECT_EQ(seen, (std::vector<int>{1, 2, 3}));
  for (size_t i = 0; i < film.pixelCount(); ++i) {
    ASSERT_EQ(film.sampleCount[i] + film.invalidCount[i], 3u) << "pixel " << i;
  }
  Film three(32, 32);
  renderCpu(data, test::cpuOptions(2, 3), three);
  expectSameFilm(film, three);

  // A stop asked for during a pass drops that pass: here, from the progress callback of the
  // fifth pass.
  Film dropped(32, 32);
  std::atomic<bool> stopNow{false};
  options = test::cpuOptions(2, 1000);
  options.stop = &stopNow;
  options.progress = [&](double f) {
    if (f > 4.5 / 1000.0) stopNow = true;
  };
  const CpuRenderStats partial = renderCpu(data, options, dropped);
  EXPECT_TRUE(partial.stopped);
  EXPECT_GE(partial.samplesDone, 4);
  EXPECT_LE(partial.samplesDone, 5);
  for (size_t i = 0; i < dropped.pixelCount(); ++i) {
    ASSERT_EQ(dropped.sampleCount[i] + dropped.invalidCount[i], uint64_t(partial.samplesDone));
  }
  // The dropped pass's tiles were taken back out bit for bit.
  Film whole(32, 32);
  renderCpu(data, test::cpuOptions(1, partial.samplesDone), whole);
  expectSameFilm(dropped, whole);
}

// ---- The Vulkan backend's batches -----------------------------------------------------------

VulkanRenderOptions vulkanOptions(uint32_t first, int spp) {
  VulkanRenderOptions options = validatedOptions(spp);
  options.firstSample = first;
  options.samplesPerFold = 8;
  options.samplesPerPass = 2;
  return options;
}

TEST(VulkanBatches, StoppedMidBatchAndContinuedGiveTheBitsOfOneRun) {
  const SceneData data = prepareConfig("cornell-box.json", 16);
  Film whole(16, 16);
  const VulkanRenderStats ref = renderVulkan(data, vulkanOptions(0, 21), whole);
  EXPECT_EQ(ref.validationErrors, 0u);
  EXPECT_TRUE(ref.open.empty());

  // Stopped after the 7th dispatch (samples 0..13: one batch folded, 6 samples open), then
  // continued from the open batch in two more runs, the second stopped after one dispatch.
  Film film(16, 16);
  std::atomic<bool> stop{false};
  VulkanRenderOptions options = vulkanOptions(0, 21);
  options.stop = &stop;
  int dispatches = 0;
  options.progress = [&](double) {
    if (++dispatches == 7) stop = true;
  };
  VulkanRenderStats first = renderVulkan(data, options, film);
  EXPECT_TRUE(first.stopped);
  EXPECT_EQ(first.samplesDone, 14);
  EXPECT_EQ(first.open.first, 8u);
  EXPECT_EQ(first.open.count, 6u);
  EXPECT_EQ(film.sampleCount[0] + film.invalidCount[0], 8u);

  stop = false;
  dispatches = 0;
  options = vulkanOptions(14, 7);
  options.stop = &stop;
  options.openBatch = &first.open;
  options.progress = [&](double) {
    if (++dispatches == 1) stop = true;
  };
  const VulkanRenderStats second = renderVulkan(data, options, film);
  EXPECT_TRUE(second.stopped);
  EXPECT_EQ(second.samplesDone, 2);
  EXPECT_TRUE(second.open.empty()) << "the batch [8, 16) was completed and folded";

  options = vulkanOptions(16, 5);
  const VulkanRenderStats third = renderVulkan(data, options, film);
  EXPECT_FALSE(third.stopped);
  EXPECT_EQ(third.validationErrors, 0u);
  expectSameFilm(film, whole);
}

TEST(VulkanBatches, AlignedSlicesMergeToTheBitsOfOneRun) {
  const SceneData data = prepareConfig("cornell-mirror.json", 16);
  Film whole(16, 16);
  renderVulkan(data, vulkanOptions(0, 30), whole);
  // Slices at batch boundaries (multiples of 8), the last one kept open and folded on merge.
  Film merged(16, 16);
  for (auto [first, count] : {std::pair{24, 6}, std::pair{0, 8}, std::pair{8, 16}}) {
    Film slice(16, 16);
    VulkanRenderOptions options = vulkanOptions(uint32_t(first), count);
    options.keepOpenBatch = true;
    const VulkanRenderStats stats = renderVulkan(data, options, slice);
    EXPECT_EQ(stats.validationErrors, 0u);
    EXPECT_EQ(stats.open.count, first == 24 ? 6u : 0u);
    stats.open.foldInto(slice);
    merged.merge(slice);
  }
  expectSameFilm(merged, whole);
}

}  // namespace
}  // namespace pt
