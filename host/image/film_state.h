// The film state: what a render has accumulated (exact sums and sample counts for a set of
// sample indices) and the settings that determined it, kept in a file so that a render can
// be continued (`render --resume`) or combined with other slices of sample indices (`merge`).
// Knows nothing of scenes: settings are opaque key=value pairs the command line fills in.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "image/image.h"
#include "image/sppm_pixels.h"

namespace pt {

// Sample indices [first, end).
struct SampleRange {
  uint32_t first = 0;
  uint32_t end = 0;

  uint32_t count() const { return end - first; }
  bool operator==(const SampleRange&) const = default;
  std::string toString() const;  // "FIRST:COUNT", as --samples takes it
};

// The first sample index of the slice `index` of `count` equal slices of `job`, with every
// boundary but the job's end a multiple of `unit` (the Vulkan backend's batch: slices merge
// to the one-run image only when they split no batch). Slices may be empty when the job has
// fewer units than tasks.
uint32_t sliceStart(SampleRange job, int index, int count, uint32_t unit);
inline SampleRange taskSlice(SampleRange job, int index, int count, uint32_t unit) {
  return SampleRange{sliceStart(job, index, count, unit), sliceStart(job, index + 1, count, unit)};
}

// Sample indices of `expected` that are in none of `have` (sorted, disjoint), in order.
std::vector<SampleRange> missingRanges(const std::vector<SampleRange>& have, SampleRange expected);

// Samples the Vulkan backend dispatched since its last fold into the film, kept when a render
// stops in the middle of a batch: the device's float sums and invalid counts per pixel. A
// resumed render uploads them and continues the batch, so its float sums come out exactly as
// an uninterrupted render's.
struct OpenBatch {
  uint32_t first = 0;             // the batch's first sample index
  uint32_t count = 0;             // samples per pixel in it so far: [first, first + count)
  std::vector<glm::vec3> sum;     // per pixel, row-major
  std::vector<uint32_t> invalid;  // per pixel

  bool empty() const { return count == 0; }
  uint64_t invalidTotal() const;
  void foldInto(Film& film) const;  // as the backend would have at the end of the batch
};

using KeyValues = std::vector<std::pair<std::string, std::string>>;

struct FilmState {
  // Everything that determines the image (scene content, resolution, seed, sampler,
  // strategy, depth, builder, backend...): resume and merge refuse a state whose settings
  // differ, naming them. Keys are unique; values hold no newline.
  KeyValues settings;
  // What is told but not compared: the scene file, the device, the slice of a job.
  KeyValues info;
  // The sample indices whose samples are in the state: sorted, disjoint, not adjacent.
  std::vector<SampleRange> ranges;
  Film film;
  // Vulkan: the last range's tail, not yet in `film` (empty otherwise).
  OpenBatch open;
  // Photon mapping (sppm): every pixel's state after the iterations of `ranges` (one range
  // from 0), which a resumed render continues from; `film` then holds one sample a pixel, the
  // estimate of those iterations. Empty for the other integrators.
  SppmPixels sppm;

  uint32_t samplesPerPixel() const;  // sample indices in `ranges`
  Film combinedFilm() const;         // film with the open batch folded in: the image's sums
  const std::string* infoValue(const std::string& key) const;
};

// A 64-bit hash of bytes (not cryptographic: it tells accidental differences apart). Stable
// across builds and machines: it is stored in state files.
uint64_t hashBytes(const void* data, size_t size, uint64_t seed = 0);
// The settings' hash, as the state file records it.
uint64_t settingsHash(const KeyValues& settings);
std::string hexHash(uint64_t hash);  // 16 hex digits

// Writes atomically (never a half-written file); InputError naming the file on failure.
void writeFilmState(const FilmState& state, const std::filesystem::path& path);

// Reads and checks a state file: InputError naming the file for one that is not a state
// file, truncated, corrupt (checksum) or inconsistent.
FilmState readFilmState(const std::filesystem::path& path);

// "seed 3 vs 0, scene 0123... vs 4567..." for the settings whose values differ between a and
// b (a key missing on one side shows as "(none)"); "" when they agree.
std::string settingsDifference(const KeyValues& a, const KeyValues& b);

struct NamedFilmState {
  std::filesystem::path path;
  FilmState state;
};

// Combines states of disjoint sample ranges rendered with the same settings, exactly: the
// result does not depend on the order the states come in, and equals the state of one render
// of all their samples. An sppm render's state is refused (InputError naming the file): its
// pixels depend on every iteration before, so slices of it do not add up. Open batches are folded
// in, but for the one that ends the merged samples: it stays open, as it would in the one render's
// state. States are added one at a time and their films merged at once, so that memory holds two
// films, not all of them.
class FilmStateMerger {
 public:
  void add(NamedFilmState named);
  // InputError naming the files for differing settings or sizes and for overlapping ranges
  // (the same message whatever the order of add()). Info entries that all states share are
  // kept.
  FilmState finish();

 private:
  struct Seen {
    std::filesystem::path path;
    int width = 0, height = 0;
    FilmState meta;  // everything but the film; the open batch until finish()
  };
  std::vector<Seen> seen_;
  Film film_;
};

// All of `states` through a FilmStateMerger.
FilmState mergeFilmStates(std::vector<NamedFilmState> states);

}  // namespace pt
