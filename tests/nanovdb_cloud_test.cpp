// pbrt-v4's nanovdb and cloud media: NanoVDB files read into sparse voxel grids
// (scene/nanovdb_file.h, voxel_grid.h) and looked up as NanoVDB samples them, their majorants,
// blackbody emission, pbrt-v4's noise and cloud density, the readers' errors, and renders on
// both backends (white furnaces; the same medium as a uniformgrid).
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <nanovdb/NanoVDB.h>
#include <nanovdb/util/GridBuilder.h>
#include <nanovdb/util/IO.h>
#include <nanovdb/util/SampleFromVoxels.h>

#include "media_scenes.h"
#include "medium.h"
#include "render/prepare_media.h"
#include "render_compare.h"
#include "scene/load_scene.h"
#include "scene/media.h"
#include "scene/pbrt/spectra.h"
#include "test_util.h"

namespace pt {
namespace {

using namespace media_scenes;

using Handle = nanovdb::GridHandle<nanovdb::HostBuffer>;

// A float grid: `value` at every voxel of [lo, hi] (index coordinates) where it is not the
// background, voxel size h, index (0, 0, 0) at `origin`.
template <typename F>
Handle makeGrid(const std::string& name, float background, nanovdb::Coord lo, nanovdb::Coord hi,
                double h, nanovdb::Vec3d origin, F value,
                nanovdb::GridClass cls = nanovdb::GridClass::FogVolume) {
  nanovdb::GridBuilder<float> builder(background, cls);
  auto acc = builder.getAccessor();
  for (int z = lo[2]; z <= hi[2]; ++z) {
    for (int y = lo[1]; y <= hi[1]; ++y) {
      for (int x = lo[0]; x <= hi[0]; ++x) {
        const float v = value(x, y, z);
        if (v != background) acc.setValue(nanovdb::Coord(x, y, z), v);
      }
    }
  }
  return builder.getHandle<>(h, origin, name);
}

// A smooth ball of density in [0, 1] with a few isolated voxels far from it (other leaves,
// and bricks between them that have none).
float ballDensity(int x, int y, int z) {
  if ((x == 20 && y == -9 && z == 3) || (x == -11 && y == 17 && z == 17)) return 0.75f;
  const float r = std::sqrt(float(x * x + y * y + z * z)) / 7.0f;
  return r < 1.0f ? (1.0f - r * r) * (0.6f + 0.4f * std::sin(float(x + 2 * y - z))) : 0.0f;
}

Handle ballGrid() {
  return makeGrid("density", 0.0f, nanovdb::Coord(-12, -10, -9), nanovdb::Coord(21, 18, 18), 0.05,
                  nanovdb::Vec3d(0.1, -0.2, 0.05), ballDensity);
}

std::filesystem::path writeFile(const test::TempDir& dir, const std::string& name, Handle a,
                                Handle b = Handle()) {
  std::vector<Handle> grids;
  grids.push_back(std::move(a));
  if (b) grids.push_back(std::move(b));
  const std::filesystem::path path = dir / name;
  nanovdb::io::writeGrids<nanovdb::HostBuffer, std::vector>(path.string(), grids);
  return path;
}

// The scene arrays medium.h reads, over `grids` alone.
PathScene gridScene(const std::vector<float>& grids) {
  PathScene s{};
  s.mediumGrids = grids.data();
  return s;
}

std::string nvdbErrorOf(const std::filesystem::path& file, const std::string& grid,
                        const std::string& temperature = "temperature") {
  try {
    readNanoVdbMedium(file, grid, temperature);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// ---- Reading and looking up --------------------------------------------------------------------

// Every voxel as NanoVDB has it, and trilinear lookups as NanoVDB's sampler gives them.
TEST(NanoVdb, SparseGridHoldsEveryVoxelAndSamplesAsNanoVdb) {
  test::TempDir dir;
  const Handle handle = ballGrid();
  const std::filesystem::path file = writeFile(dir, "ball.nvdb", ballGrid());
  const NanoVdbMediumGrids read = readNanoVdbMedium(file, "density", "temperature");
  EXPECT_FALSE(read.temperature.has_value());
  const std::vector<float> packed = packVoxelGrid(read.density);
  EXPECT_EQ(packedVoxelGridFloats(packed.data()), packed.size());
  const PathScene scene = gridScene(packed);
  const VoxelGrid vg = loadVoxelGrid(scene, 0u);
  const nanovdb::NanoGrid<float>& grid = *handle.grid<float>();
  auto acc = grid.getAccessor();
  // Bounds: the grid's world box, as pbrt-v4 takes them.
  for (int a = 0; a < 3; ++a) {
    EXPECT_DOUBLE_EQ(read.boundsMin[a], grid.worldBBox().min()[a]);
    EXPECT_DOUBLE_EQ(read.boundsMax[a], grid.worldBBox().max()[a]);
  }
  int nonzero = 0;
  for (int z = -14; z <= 22; ++z) {
    for (int y = -12; y <= 20; ++y) {
      for (int x = -14; x <= 23; ++x) {
        const float v = voxelGridValue(scene, vg, ivec3(x, y, z));
        ASSERT_EQ(v, acc.getValue(nanovdb::Coord(x, y, z))) << x << " " << y << " " << z;
        nonzero += v != 0.0f;
      }
    }
  }
  EXPECT_GT(nonzero, 1000);
  nanovdb::SampleFromVoxels<nanovdb::NanoTree<float>, 1, false> sampler(grid.tree());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 20000; ++i) {
    const glm::dvec3 p =
        read.boundsMin + (read.boundsMax - read.boundsMin) * glm::dvec3(u(rng), u(rng), u(rng));
    const float ours = voxelGridLookup(scene, 0u, vec3(p));
    const float theirs =
        sampler(grid.worldToIndexF(nanovdb::Vec3f(float(p.x), float(p.y), float(p.z))));
    ASSERT_NEAR(ours, theirs, 2e-5f) << p.x << " " << p.y << " " << p.z;
  }
}

// Per cell of the majorant grid, no density in the cell is above its majorant; the largest
// majorant is the largest density (not a loose bound).
TEST(NanoVdb, MajorantsBoundTheDensityInTheirCells) {
  test::TempDir dir;
  MediumParams p;
  p.type = kMediumNanoVdb;
  p.nanovdb = std::make_shared<const NanoVdbMediumGrids>(
      readNanoVdbMedium(writeFile(dir, "ball.nvdb", ballGrid()), "density", "temperature"));
  Scene scene;
  const Medium m = scene.media[addMedium(scene, "ball", p)];
  EXPECT_EQ(m.size, uvec3(kNanoVdbMajorantRes));
  const std::vector<float> majorants = majorantGrid(m, scene.mediumGrids);
  ASSERT_EQ(majorants.size(),
            size_t(kNanoVdbMajorantRes) * kNanoVdbMajorantRes * kNanoVdbMajorantRes);
  const PathScene s = gridScene(scene.mediumGrids);
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  float densest = 0.0f;
  for (int i = 0; i < 200000; ++i) {
    const vec3 f(u(rng), u(rng), u(rng));
    const vec3 p = m.boundsMin + (m.boundsMax - m.boundsMin) * f;
    const ivec3 c = glm::min(ivec3(f * float(kNanoVdbMajorantRes)), ivec3(kNanoVdbMajorantRes - 1));
    const float d = voxelGridLookup(s, m.density, p);
    densest = std::max(densest, d);
    ASSERT_LE(d, majorants[(size_t(c.z) * kNanoVdbMajorantRes + c.y) * kNanoVdbMajorantRes + c.x]);
  }
  // The largest majorant is the largest voxel (the ball's or an isolated one).
  const Handle ball = ballGrid();
  float largest = 0.0f;
  const auto* leaves = ball.grid<float>()->tree().getFirstLeaf();
  for (uint32_t i = 0; i < ball.grid<float>()->tree().nodeCount(0); ++i) {
    for (uint32_t v = 0; v < kBrickVoxels; ++v) largest = std::max(largest, leaves[i].getValue(v));
  }
  EXPECT_EQ(*std::max_element(majorants.begin(), majorants.end()), largest);
  EXPECT_GT(densest, 0.9f * largest);
}

// pbrt-v4's emission: Lescale times its normalized blackbody at (T - temperatureoffset) *
// temperaturescale, here against the spectrum integrated anew (as pbrt-v4's film records it:
// not normalized to luminance 1, unlike its lights; a render of a constant grid at 1500 and
// 6500 K agreed with pbrt-v4's within its noise, 2 %, where dividing by the integral of y-bar
// was 103 times too dark).
TEST(NanoVdb, BlackbodyEmissionFollowsTheTemperatureGrid) {
  test::TempDir dir;
  const auto hot = [](int x, int, int) { return x < 0 ? 1500.0f : 2400.0f; };
  const std::filesystem::path file =
      writeFile(dir, "fire.nvdb", ballGrid(),
                makeGrid("temperature", 300.0f, nanovdb::Coord(-8), nanovdb::Coord(8), 0.05,
                         nanovdb::Vec3d(0.1, -0.2, 0.05), hot));
  MediumParams p;
  p.type = kMediumNanoVdb;
  p.nanovdb =
      std::make_shared<const NanoVdbMediumGrids>(readNanoVdbMedium(file, "density", "temperature"));
  ASSERT_TRUE(p.nanovdb->temperature.has_value());
  EXPECT_EQ(p.nanovdb->temperatureMin, 300.0f);
  EXPECT_EQ(p.nanovdb->temperatureMax, 2400.0f);
  p.LeScale = 2.0;
  p.temperatureOffset = 100.0;
  p.temperatureScale = 2.0;
  Scene scene;
  const Medium m = scene.media[addMedium(scene, "fire", p)];
  ASSERT_EQ(m.emissive, kEmitsBlackbody);
  const PathScene s = gridScene(scene.mediumGrids);
  // Voxel centres: index i is at 0.1 + 0.05 i in x (and likewise in y, z).
  const auto at = [](int x, int y, int z) {
    return vec3(0.1f + 0.05f * float(x), -0.2f + 0.05f * float(y), 0.05f + 0.05f * float(z));
  };
  for (const auto& [point, kelvin] :
       {std::pair{at(-3, 1, 2), 2800.0}, std::pair{at(3, -2, 0), 4600.0},
        std::pair{at(15, 15, 15), 400.0}}) {
    const vec3 Le = mediumPropertiesAt(s, m, point).Le;
    // pbrt-v4's film: XYZ the sums of the matching functions times the radiance, per nm.
    const glm::dvec3 want = 2.0 * spectra::xyzToLinearSrgb() *
                            spectra::toXyz(spectra::blackbody(kelvin)) * spectra::cieYIntegral();
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(Le[c], want[c], 2e-4 * std::max(want[c], 1e-3)) << kelvin << " K, channel " << c;
    }
  }
  // Below 100 K nothing is emitted; and where T never passes 100 K the medium does not emit.
  p.temperatureOffset = 2400.0;
  Scene cold;
  EXPECT_EQ(cold.media[addMedium(cold, "cold", p)].emissive, kEmitsNothing);
}

// The file's problems, one line each, naming it.
TEST(NanoVdb, BadFilesAreOneLineErrors) {
  test::TempDir dir;
  const std::filesystem::path ball = writeFile(dir, "ball.nvdb", ballGrid());
  EXPECT_EQ(nvdbErrorOf(dir / "none.nvdb", "density"),
            (dir / "none.nvdb").string() + ": Unable to open file named \"" +
                (dir / "none.nvdb").string() + "\" for input");
  EXPECT_EQ(nvdbErrorOf(ball, "smoke"), ball.string() + ": no grid named 'smoke'");
  const std::filesystem::path levelFile =
      writeFile(dir, "level.nvdb",
                makeGrid(
                    "density", 0.0f, nanovdb::Coord(0), nanovdb::Coord(3), 1.0, nanovdb::Vec3d(0.0),
                    [](int, int, int) { return 0.5f; }, nanovdb::GridClass::LevelSet));
  EXPECT_EQ(nvdbErrorOf(levelFile, "density"),
            levelFile.string() +
                ": grid 'density' is not a fog volume (pbrt-v4 reads densities and temperatures "
                "from fog volumes)");
  const std::filesystem::path negative = writeFile(
      dir, "negative.nvdb",
      makeGrid("density", 0.0f, nanovdb::Coord(0), nanovdb::Coord(3), 1.0, nanovdb::Vec3d(0.0),
               [](int x, int, int) { return x == 2 ? -1.0f : 0.5f; }));
  EXPECT_EQ(nvdbErrorOf(negative, "density"),
            negative.string() +
                ": grid 'density' holds -1.000000 (densities must be non-negative and finite)");
  // A damaged file: a byte of the grid's own header changed (NanoVDB's checksum covers the
  // headers of the grid and its nodes, not the values).
  std::string bytes = test::readFile(ball);
  bytes[bytes.size() - ballGrid().size() + 300] ^= 0x55;
  const std::filesystem::path damaged = dir.write("damaged.nvdb", bytes);
  EXPECT_NE(nvdbErrorOf(damaged, "density").find(damaged.string() + ": grid 'density' is damaged"),
            std::string::npos)
      << nvdbErrorOf(damaged, "density");
  // Not a NanoVDB file at all.
  const std::filesystem::path text = dir.write("text.nvdb", "not a grid\n");
  EXPECT_EQ(nvdbErrorOf(text, "density").rfind(text.string() + ": ", 0), 0u)
      << nvdbErrorOf(text, "density");
}

// Both readers: the file relative to the scene, and its errors at the parameter.
TEST(NanoVdb, ReadersFindTheFileBesideTheScene) {
  test::TempDir dir;
  writeFile(dir, "ball.nvdb", ballGrid());
  const std::string shape =
      "AttributeBegin\nMaterial \"interface\"\nShape \"sphere\"\nAttributeEnd\n";
  const std::filesystem::path pbrt = dir.write(
      "scene.pbrt",
      "Camera \"perspective\"\nWorldBegin\n"
      "MakeNamedMedium \"smoke\" \"string type\" \"nanovdb\" \"string filename\" \"ball.nvdb\" "
      "\"rgb sigma_s\" [1 2 3] \"float scale\" 2\n"
      "MediumInterface \"smoke\" \"\"\n" +
          shape);
  const Scene s = loadScene(pbrt);
  ASSERT_EQ(s.media.size(), 1u);
  EXPECT_EQ(s.media[0].type, kMediumNanoVdb);
  EXPECT_EQ(s.media[0].sigmaS, vec3(2.0f, 4.0f, 6.0f));
  const std::filesystem::path missing = dir.write(
      "missing.pbrt",
      "Camera \"perspective\"\nWorldBegin\n"
      "MakeNamedMedium \"smoke\" \"string type\" \"nanovdb\" \"string filename\" \"fire.nvdb\"\n"
      "MediumInterface \"smoke\" \"\"\n" +
          shape);
  try {
    loadScene(missing);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(missing.string() + ":3:", 0), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find("fire.nvdb: Unable to open"), std::string::npos);
  }
  const std::filesystem::path json =
      dir.write("scene.json",
                R"({"camera": {"position": [0, 0, 5], "target": [0, 0, 0]},
          "materials": [{"name": "i", "type": "interface"}],
          "media": [{"name": "smoke", "type": "nanovdb", "filename": "ball.nvdb", "g": 0.3},
                    {"name": "c", "type": "cloud", "density": 3, "p0": [-1, -1, -1]}],
          "shapes": [{"type": "quad", "material": "i", "interior": "smoke",
                      "vertices": [[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]},
                     {"type": "quad", "material": "i", "interior": "c",
                      "vertices": [[0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]]}]})");
  const Scene j = loadScene(json);
  ASSERT_EQ(j.media.size(), 2u);
  EXPECT_EQ(j.media[0].type, kMediumNanoVdb);
  EXPECT_EQ(j.media[0].g, 0.3f);
  EXPECT_EQ(j.media[1].type, kMediumCloud);
  EXPECT_EQ(j.media[1].Le, vec3(3.0f, 1.0f, 5.0f));  // density, wispiness, frequency
  EXPECT_EQ(j.media[1].boundsMin, vec3(-1.0f));
}

// ---- pbrt-v4's noise and cloud ------------------------------------------------------------------

// Noise and DNoise at these points as pbrt-v4's own util/noise.cpp computes them (compiled from
// its source, g++ 12, float), and the lattice points where noise is zero.
TEST(Noise, IsPbrtV4sPerlinNoise) {
  std::vector<float> table(kNoisePermutationSize);
  for (uint i = 0; i < kNoisePermutationSize; ++i) {
    table[i] = glm::uintBitsToFloat(uint(kNoisePermutation[i]));
  }
  const PathScene s = gridScene(table);
  struct Reference {
    vec3 p;
    float noise;
    vec3 gradient;
  };
  const Reference pbrt[] = {
      {{0.3f, 0.7f, 0.1f}, -0.0971814692f, {-0.390983373f, 0.379614532f, 0.284910202f}},
      {{-1.25f, 2.5f, 3.75f}, 0.39238739f, {-0.453153253f, 0.681477785f, 0.291281939f}},
      {{10.1f, -20.2f, 30.3f}, 0.340536952f, {0.455698371f, 1.05322897f, 0.830027461f}},
      {{255.5f, 256.25f, -0.125f}, -0.139493883f, {-1.52051008f, 0.405214727f, 0.111119449f}},
      {{1e6f + 0.37f, 3.3f, -7.9f}, -0.164259896f, {0.0f, -0.943696499f, 0.300607085f}},
  };
  for (const Reference& r : pbrt) {
    EXPECT_NEAR(perlinNoise(s, 0u, r.p), r.noise, 1e-6f);
    const vec3 g = perlinNoiseGradient(s, 0u, r.p);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(g[a], r.gradient[a], 2e-4f) << a;
  }
  for (int i = -3; i < 300; i += 7) {
    EXPECT_EQ(perlinNoise(s, 0u, vec3(float(i), float(2 * i), float(-i))), 0.0f);
  }
  // A wrong permutation (two entries swapped) is not pbrt-v4's noise.
  std::swap(table[0], table[1]);
  std::swap(table[256], table[257]);
  float worst = 0.0f;
  for (const Reference& r : pbrt)
    worst = std::max(worst, std::fabs(perlinNoise(s, 0u, r.p) - r.noise));
  EXPECT_GT(worst, 1e-3f);
}

TEST(Noise, CloudDensityStaysInTheUnitInterval) {
  std::vector<float> table(kNoisePermutationSize);
  for (uint i = 0; i < kNoisePermutationSize; ++i) {
    table[i] = glm::uintBitsToFloat(uint(kNoisePermutation[i]));
  }
  const PathScene s = gridScene(table);
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-2.0f, 2.0f);
  int between = 0;
  for (int i = 0; i < 20000; ++i) {
    const vec3 p(u(rng), u(rng), u(rng));
    const float d = cloudDensity(s, 0u, p, 2.0f, 1.0f, 5.0f);
    ASSERT_GE(d, 0.0f);
    ASSERT_LE(d, 1.0f);
    between += d > 0.0f && d < 1.0f;
    if (p.y < 0.0f) ASSERT_EQ(d, 1.0f);  // filled below y = 0 (2 (0.5 - y) >= 1)
  }
  EXPECT_GT(between, 1000);
}

// ---- Renders -------------------------------------------------------------------------------

Medium nanoVdbMedium(Scene& scene, const NanoVdbMediumGrids& grids, vec3 sigmaA, vec3 sigmaS) {
  MediumParams p;
  p.type = kMediumNanoVdb;
  p.sigmaA = sigmaA;
  p.sigmaS = sigmaS;
  p.nanovdb = std::make_shared<const NanoVdbMediumGrids>(grids);
  return scene.media[addMedium(scene, "vdb", p)];
}

// White furnaces: albedo-1 nanovdb and cloud media inside the sphere render the environment.
TEST(MediaBothBackends, NanoVdbWhiteFurnaceRendersTheEnvironment) {
  test::TempDir dir;
  // The ball, 0.05 per voxel, centred near the origin: well inside the unit sphere.
  const NanoVdbMediumGrids grids =
      readNanoVdbMedium(writeFile(dir, "ball.nvdb",
                                  makeGrid("density", 0.0f, nanovdb::Coord(-8), nanovdb::Coord(8),
                                           0.05, nanovdb::Vec3d(0.0), ballDensity)),
                        "density", "temperature");
  Scene scene;
  const Medium m = nanoVdbMedium(scene, grids, vec3(0.0f), vec3(2.0f, 4.0f, 8.0f));
  expectTheEnvironment(furnace(m, scene.mediumGrids, 96));
}

TEST(MediaBothBackends, CloudWhiteFurnaceRendersTheEnvironment) {
  MediumParams p;
  p.type = kMediumCloud;
  p.sigmaA = vec3(0.0f);
  p.sigmaS = vec3(2.0f, 4.0f, 8.0f);
  p.cloudDensity = 2.0;
  p.p0 = glm::dvec3(-0.7);
  p.p1 = glm::dvec3(0.7);
  Scene scene;
  const Medium m = scene.media[addMedium(scene, "c", p)];
  expectTheEnvironment(furnace(m, scene.mediumGrids, 96));
}

// The same densities as a nanovdb grid and as a uniformgrid (pbrt-v4's SampledGrid puts its
// values at the centres of cells over p0-p1, NanoVDB at integer index points: the same field
// where the uniformgrid's bounds are shifted by half a voxel) render the same image, within
// noise; without the shift they do not, so the comparison can tell.
TEST(NanoVdb, RendersAsTheSameDensitiesInAUniformGrid) {
  constexpr int kN = 5;
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  // Next to nothing on the first layer of each axis: pbrt-v4's bounds of a NanoVDB grid are its
  // world box, which starts at its first active voxel and cuts the interpolation below it off
  // (and ends a voxel beyond its last); the uniformgrid's field goes on to zero below. A value
  // of 1e-6 keeps the layer active and what is cut off negligible.
  std::vector<float> values(kN * kN * kN);
  for (int i = 0; i < kN * kN * kN; ++i) {
    const bool first = i % kN == 0 || (i / kN) % kN == 0 || i / (kN * kN) == 0;
    values[size_t(i)] = first ? 1e-6f : u(rng) < 0.3f ? 0.0f : u(rng);
  }
  test::TempDir dir;
  const float h = 0.4f;  // voxels 0..4 at -0.6 + 0.4 i: bounds -0.6 .. 1.4
  const NanoVdbMediumGrids grids = readNanoVdbMedium(
      writeFile(
          dir, "g.nvdb",
          makeGrid("density", 0.0f, nanovdb::Coord(0), nanovdb::Coord(kN - 1), h,
                   nanovdb::Vec3d(-0.6),
                   [&](int x, int y, int z) { return values[size_t((z * kN + y) * kN + x)]; })),
      "density", "temperature");
  const vec3 sigmaA(0.5f), sigmaS(2.0f);
  const auto render = [&](int which) {
    Scene scene;
    scene.camera = camera(vec3(0.4f, 0.4f, -4.0f), vec3(0.4f), 20.0f, 16);
    scene.materials = {Material{vec3(0.0f), kMaterialInterface, vec3(0.0f), 0}};
    scene.lights = {environment(1.0f)};
    if (which == 0) {
      scene.media = {nanoVdbMedium(scene, grids, sigmaA, sigmaS)};
    } else {
      // Cells of size h centred on the voxels: p0 half a voxel below the first (shift), or not.
      const float lo = which == 1 ? -0.6f - 0.5f * h : -0.6f;
      // The uniformgrid's values fall to zero over the half cell beyond the outer centres;
      // the nanovdb grid's over a whole voxel: pad with a ring of zeros to hold the same field.
      std::vector<float> padded((kN + 2) * (kN + 2) * (kN + 2), 0.0f);
      for (int z = 0; z < kN; ++z) {
        for (int y = 0; y < kN; ++y) {
          for (int x = 0; x < kN; ++x) {
            padded[size_t(((z + 1) * (kN + 2) + y + 1) * (kN + 2) + x + 1)] =
                values[size_t((z * kN + y) * kN + x)];
          }
        }
      }
      scene.media = {uniformGrid(scene, vec3(lo - h), vec3(lo + h * float(kN + 1)), uvec3(kN + 2),
                                 padded, sigmaA, sigmaS)};
    }
    addShape(scene, box(vec3(-1.5f), vec3(1.5f)), 0, MediumInterface{0, kVacuum});
    const SceneData data = prepare(scene, 64);
    Film film(16, 16);
    renderCpu(data, test::cpuOptions(2, 256), film);
    return film.resolve();
  };
  const Image vdb = render(0), shifted = render(1), unshifted = render(2);
  const auto difference = [&](const Image& other) {
    double sum = 0.0, sumSquares = 0.0;
    for (size_t i = 0; i < vdb.pixels.size(); ++i) {
      const double d = double(vdb.pixels[i].y) - double(other.pixels[i].y);
      sum += d;
      sumSquares += d * d;
    }
    const double n = double(vdb.pixels.size());
    const double mean = sum / n;
    return std::pair{mean, std::sqrt(std::max(0.0, sumSquares / n - mean * mean) / n)};
  };
  const auto [same, seSame] = difference(shifted);
  EXPECT_LT(seSame, 0.01);
  EXPECT_LT(std::fabs(same), 4.0 * seSame + 1e-4) << "se " << seSame;
  const auto [moved, seMoved] = difference(unshifted);
  EXPECT_GT(std::fabs(moved), 6.0 * seMoved) << "se " << seMoved;
}

}  // namespace
}  // namespace pt
