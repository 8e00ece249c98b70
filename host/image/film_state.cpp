// Film state files; see film_state.h. The file is a text header (readable with `head`) and
// a binary body, ended by a checksum of everything before it:
//
//   pt film state 1
//   width 256
//   height 256
//   samples 0:64            sample ranges FIRST:COUNT, comma-separated
//   open 48:8               only when a Vulkan batch was left open: its first sample, count
//   setting backend=cpu     one line per setting, in the order they were given
//   settings-hash 0123456789abcdef
//   info scene=...          one line per info entry
//   sppm 33                 only for an sppm render: the bytes of its state per pixel
//   data 123456             the body's length in bytes; the body follows this line
//
// The body holds, per pixel in row-major order: the valid and invalid sample counts (LEB128
// varints), then per channel the ExactSum as a byte saying which of its limbs are non-zero
// followed by those limbs (little-endian); then, with an open batch, per pixel its three
// float sums and its invalid count (little-endian); then, for an sppm render, per pixel its
// radius, photon count, flux and direct-light sum (8 floats) and its invalid flag (a byte).
// The last 8 bytes are hashBytes() of everything before them, little-endian.
#include "image/film_state.h"

#include <algorithm>
#include <bit>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <set>
#include <string_view>

#include "image/file_io.h"

namespace pt {
namespace {

namespace fs = std::filesystem;

constexpr std::string_view kMagic = "pt film state ";
constexpr int kVersion = 1;
constexpr size_t kMaxHeaderBytes = 1 << 20;
constexpr uint64_t kMaxPixels = uint64_t(1) << 28;
constexpr uint64_t kSppmPixelBytes = 8 * 4 + 1;

[[noreturn]] void failState(const fs::path& path, const std::string& what) {
  throw InputError(path.string() + ": " + what);
}

// ---- Encoding -------------------------------------------------------------------------------

void putVarint(Bytes& out, uint64_t v) {
  while (v >= 0x80) {
    out.push_back(static_cast<unsigned char>(v | 0x80));
    v >>= 7;
  }
  out.push_back(static_cast<unsigned char>(v));
}

void putLittle(Bytes& out, uint64_t v, int bytes) {
  for (int b = 0; b < bytes; ++b) out.push_back(static_cast<unsigned char>(v >> (8 * b)));
}

std::string rangesText(const std::vector<SampleRange>& ranges) {
  std::string s;
  for (const SampleRange& r : ranges) s += (s.empty() ? "" : ",") + r.toString();
  return s.empty() ? "none" : s;
}

// ---- Decoding -------------------------------------------------------------------------------

// Reads the body with every access bounds-checked: a state file is input, however it was
// made.
class Reader {
 public:
  Reader(const fs::path& path, const unsigned char* begin, const unsigned char* end)
      : path_(path), p_(begin), end_(end) {}

  uint64_t varint() {
    uint64_t v = 0;
    for (int shift = 0; shift < 64; shift += 7) {
      const unsigned char byte = next();
      v |= uint64_t(byte & 0x7F) << shift;
      if (!(byte & 0x80)) return v;
    }
    corrupt("a count is malformed");
  }

  uint64_t little(int bytes) {
    if (end_ - p_ < bytes) corrupt("the body ends early");
    uint64_t v = 0;
    for (int b = 0; b < bytes; ++b) v |= uint64_t(p_[b]) << (8 * b);
    p_ += bytes;
    return v;
  }

  unsigned char next() {
    if (p_ == end_) corrupt("the body ends early");
    return *p_++;
  }

  bool atEnd() const { return p_ == end_; }

  [[noreturn]] void corrupt(const std::string& what) const {
    failState(path_, "corrupt film state: " + what);
  }

 private:
  const fs::path& path_;
  const unsigned char* p_;
  const unsigned char* end_;
};

bool parseUnsigned(std::string_view text, uint64_t& value) {
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  return ec == std::errc() && end == text.data() + text.size() && !text.empty();
}

// "FIRST:COUNT" with COUNT > 0 and FIRST + COUNT <= 2^32 - 1.
bool parseRange(std::string_view text, SampleRange& range) {
  const size_t colon = text.find(':');
  uint64_t first = 0, count = 0;
  if (colon == std::string_view::npos || !parseUnsigned(text.substr(0, colon), first) ||
      !parseUnsigned(text.substr(colon + 1), count) || count == 0 || first + count > UINT32_MAX) {
    return false;
  }
  range = SampleRange{uint32_t(first), uint32_t(first + count)};
  return true;
}

void splitKeyValue(std::string_view text, KeyValues& into, const fs::path& path, const char* what) {
  const size_t eq = text.find('=');
  if (eq == 0 || eq == std::string_view::npos) {
    failState(path, std::string("corrupt film state: malformed ") + what + " '" +
                        std::string(text) + "'");
  }
  into.emplace_back(std::string(text.substr(0, eq)), std::string(text.substr(eq + 1)));
}

void checkUniqueKeys(const KeyValues& values, const fs::path& path) {
  std::set<std::string> seen;
  for (const auto& [key, value] : values) {
    if (!seen.insert(key).second) failState(path, "corrupt film state: '" + key + "' given twice");
  }
}

// Sorted, disjoint and not adjacent: the one form a set of ranges is written in.
bool normalised(const std::vector<SampleRange>& ranges) {
  for (size_t i = 0; i < ranges.size(); ++i) {
    if (ranges[i].first >= ranges[i].end) return false;
    if (i > 0 && ranges[i - 1].end >= ranges[i].first) return false;
  }
  return true;
}

std::vector<SampleRange> coalesce(std::vector<SampleRange> ranges) {
  std::sort(ranges.begin(), ranges.end(),
            [](const SampleRange& a, const SampleRange& b) { return a.first < b.first; });
  std::vector<SampleRange> out;
  for (const SampleRange& r : ranges) {
    if (!out.empty() && out.back().end == r.first) {
      out.back().end = r.end;
    } else {
      out.push_back(r);
    }
  }
  return out;
}

}  // namespace

// ---- Ranges and slices ----------------------------------------------------------------------

std::string SampleRange::toString() const {
  return std::to_string(first) + ":" + std::to_string(count());
}

uint32_t sliceStart(SampleRange job, int index, int count, uint32_t unit) {
  if (index <= 0) return job.first;
  if (index >= count) return job.end;
  const uint64_t even = job.first + uint64_t(job.count()) * uint64_t(index) / uint64_t(count);
  const uint64_t aligned = unit > 1 ? even - even % unit : even;
  return uint32_t(std::max<uint64_t>(aligned, job.first));
}

std::vector<SampleRange> missingRanges(const std::vector<SampleRange>& have, SampleRange expected) {
  std::vector<SampleRange> missing;
  uint32_t at = expected.first;
  for (const SampleRange& r : have) {
    if (r.end <= at) continue;
    if (r.first >= expected.end) break;
    if (r.first > at) missing.push_back(SampleRange{at, r.first});
    at = std::max(at, r.end);
  }
  if (at < expected.end) missing.push_back(SampleRange{at, expected.end});
  return missing;
}

uint64_t OpenBatch::invalidTotal() const {
  uint64_t total = 0;
  for (uint32_t n : invalid) total += n;
  return total;
}

void OpenBatch::foldInto(Film& film) const {
  if (empty()) return;
  PT_CHECK(sum.size() == film.pixelCount() && invalid.size() == film.pixelCount(),
           "open batch and film sizes differ");
  for (size_t i = 0; i < sum.size(); ++i) {
    film.addSums(i, sum[i], uint64_t(count) - invalid[i], invalid[i]);
  }
}

// ---- FilmState ------------------------------------------------------------------------------

uint32_t FilmState::samplesPerPixel() const {
  uint32_t n = 0;
  for (const SampleRange& r : ranges) n += r.count();
  return n;
}

Film FilmState::combinedFilm() const {
  Film combined = film;
  open.foldInto(combined);
  return combined;
}

const std::string* FilmState::infoValue(const std::string& key) const {
  for (const auto& [k, v] : info) {
    if (k == key) return &v;
  }
  return nullptr;
}

// Eight bytes at a time through splitmix64's finaliser (a bijection with full avalanche),
// the length folded in first so that trailing zeros count.
uint64_t hashBytes(const void* data, size_t size, uint64_t seed) {
  auto mix = [](uint64_t x) {
    x ^= x >> 30;
    x *= 0xBF58476D1CE4E5B9ull;
    x ^= x >> 27;
    x *= 0x94D049BB133111EBull;
    return x ^ (x >> 31);
  };
  const auto* p = static_cast<const unsigned char*>(data);
  uint64_t h = mix(seed ^ (uint64_t(size) * 0x9E3779B97F4A7C15ull));
  for (size_t i = 0; i < size; i += 8) {
    uint64_t word = 0;
    for (size_t b = 0; b < 8 && i + b < size; ++b) word |= uint64_t(p[i + b]) << (8 * b);
    h = mix(h ^ word) + 0x9E3779B97F4A7C15ull;
  }
  return mix(h);
}

uint64_t settingsHash(const KeyValues& settings) {
  std::string text;
  for (const auto& [key, value] : settings) text += key + "=" + value + "\n";
  return hashBytes(text.data(), text.size());
}

std::string hexHash(uint64_t hash) {
  char text[17];
  std::snprintf(text, sizeof(text), "%016llx", (unsigned long long)hash);
  return text;
}

std::string settingsDifference(const KeyValues& a, const KeyValues& b) {
  auto find = [](const KeyValues& values, const std::string& key) -> const std::string* {
    for (const auto& [k, v] : values) {
      if (k == key) return &v;
    }
    return nullptr;
  };
  std::string diff;
  auto note = [&](const std::string& key, const std::string* x, const std::string* y) {
    diff +=
        (diff.empty() ? "" : ", ") + key + " " + (x ? *x : "(none)") + " vs " + (y ? *y : "(none)");
  };
  for (const auto& [key, value] : a) {
    const std::string* other = find(b, key);
    if (!other || *other != value) note(key, &value, other);
  }
  for (const auto& [key, value] : b) {
    if (!find(a, key)) note(key, nullptr, &value);
  }
  return diff;
}

// ---- Writing --------------------------------------------------------------------------------

void writeFilmState(const FilmState& state, const fs::path& path) {
  const Film& film = state.film;
  PT_CHECK(normalised(state.ranges), "film state ranges must be sorted and disjoint");
  PT_CHECK(state.open.empty() || (!state.ranges.empty() &&
                                  state.open.first + state.open.count == state.ranges.back().end &&
                                  state.open.first >= state.ranges.back().first),
           "an open batch must end the last range");

  Bytes body;
  body.reserve(film.pixelCount() * 60);
  for (size_t i = 0; i < film.pixelCount(); ++i) {
    putVarint(body, film.sampleCount[i]);
    putVarint(body, film.invalidCount[i]);
    for (const ExactSum& s : film.exact[i]) {
      unsigned char mask = 0;
      for (int l = 0; l < ExactSum::kLimbs; ++l) mask |= (s.limb[l] != 0 ? 1 : 0) << l;
      body.push_back(mask);
      for (int l = 0; l < ExactSum::kLimbs; ++l) {
        if (s.limb[l] != 0) putLittle(body, s.limb[l], 8);
      }
    }
  }
  if (!state.open.empty()) {
    PT_CHECK(state.open.sum.size() == film.pixelCount() &&
                 state.open.invalid.size() == film.pixelCount(),
             "open batch and film sizes differ");
    for (size_t i = 0; i < film.pixelCount(); ++i) {
      for (int c = 0; c < 3; ++c) putLittle(body, std::bit_cast<uint32_t>(state.open.sum[i][c]), 4);
      putLittle(body, state.open.invalid[i], 4);
    }
  }
  if (!state.sppm.empty()) {
    PT_CHECK(state.sppm.size() == film.pixelCount() && state.open.empty() &&
                 state.ranges.size() <= 1 && (state.ranges.empty() || state.ranges[0].first == 0),
             "an sppm state has a record per pixel, iterations from 0 and no open batch");
    for (const SppmPixelRecord& p : state.sppm) {
      for (float f : {p.radius, p.n, p.tau.x, p.tau.y, p.tau.z, p.ldSum.x, p.ldSum.y, p.ldSum.z}) {
        putLittle(body, std::bit_cast<uint32_t>(f), 4);
      }
      body.push_back(p.invalid ? 1 : 0);
    }
  }

  std::string header = std::string(kMagic) + std::to_string(kVersion) + "\n";
  header += "width " + std::to_string(film.width) + "\n";
  header += "height " + std::to_string(film.height) + "\n";
  header += "samples " + rangesText(state.ranges) + "\n";
  if (!state.open.empty()) {
    header += "open " +
              SampleRange{state.open.first, state.open.first + state.open.count}.toString() + "\n";
  }
  for (const auto& [key, value] : state.settings) {
    PT_CHECK(value.find('\n') == std::string::npos, "setting values are one line");
    header += "setting " + key + "=" + value + "\n";
  }
  header += "settings-hash " + hexHash(settingsHash(state.settings)) + "\n";
  for (const auto& [key, value] : state.info) {
    std::string oneLine = value;
    std::replace(oneLine.begin(), oneLine.end(), '\n', ' ');
    header += "info " + key + "=" + oneLine + "\n";
  }
  if (!state.sppm.empty()) header += "sppm " + std::to_string(kSppmPixelBytes) + "\n";
  header += "data " + std::to_string(body.size()) + "\n";

  Bytes file(header.begin(), header.end());
  file.insert(file.end(), body.begin(), body.end());
  putLittle(file, hashBytes(file.data(), file.size()), 8);
  writeFileAtomically(path, file);
}

// ---- Reading --------------------------------------------------------------------------------

FilmState readFilmState(const fs::path& path) {
  const Bytes bytes = readWholeFile(path, "a film state file");
  const std::string_view all(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  if (!all.starts_with(kMagic)) {
    failState(path, "not a pt film state (it does not begin with '" + std::string(kMagic) + "')");
  }

  // The header, line by line up to "data N".
  FilmState state;
  uint64_t width = 0, height = 0, dataSize = 0, sppmBytes = 0;
  bool haveSamples = false, haveData = false;
  std::string recordedHash;
  SampleRange openRange;
  size_t pos = 0;
  for (int line = 0; !haveData; ++line) {
    const size_t eol = all.find('\n', pos);
    if (eol == std::string_view::npos || eol > kMaxHeaderBytes) {
      failState(path, "truncated film state: the header ends before its 'data' line");
    }
    const std::string_view text = all.substr(pos, eol - pos);
    pos = eol + 1;
    if (line == 0) {
      uint64_t version = 0;
      if (!parseUnsigned(text.substr(kMagic.size()), version)) {
        failState(path, "corrupt film state: malformed first line");
      }
      if (version != kVersion) {
        failState(path, "film state version " + std::to_string(version) +
                            "; this pt reads version " + std::to_string(kVersion));
      }
      continue;
    }
    const size_t space = text.find(' ');
    const std::string_view key = text.substr(0, space);
    const std::string_view value =
        space == std::string_view::npos ? std::string_view() : text.substr(space + 1);
    auto number = [&](uint64_t& into) {
      if (!parseUnsigned(value, into)) {
        failState(path, "corrupt film state: malformed line '" + std::string(text) + "'");
      }
    };
    if (key == "width") {
      number(width);
    } else if (key == "height") {
      number(height);
    } else if (key == "samples") {
      haveSamples = true;
      if (value != "none") {
        for (size_t start = 0; start <= value.size();) {
          const size_t comma = std::min(value.find(',', start), value.size());
          SampleRange r;
          if (!parseRange(value.substr(start, comma - start), r)) {
            failState(path,
                      "corrupt film state: malformed sample ranges '" + std::string(value) + "'");
          }
          state.ranges.push_back(r);
          start = comma + 1;
        }
      }
    } else if (key == "open") {
      if (!parseRange(value, openRange)) {
        failState(path, "corrupt film state: malformed open batch '" + std::string(value) + "'");
      }
    } else if (key == "setting") {
      splitKeyValue(value, state.settings, path, "setting");
    } else if (key == "settings-hash") {
      recordedHash = std::string(value);
    } else if (key == "info") {
      splitKeyValue(value, state.info, path, "info entry");
    } else if (key == "sppm") {
      number(sppmBytes);
      if (sppmBytes != kSppmPixelBytes) {
        failState(path, "corrupt film state: sppm state of " + std::to_string(sppmBytes) +
                            " bytes per pixel; this pt writes " + std::to_string(kSppmPixelBytes));
      }
    } else if (key == "data") {
      number(dataSize);
      haveData = true;
    } else {
      failState(path, "corrupt film state: unknown header line '" + std::string(text) + "'");
    }
  }
  if (width == 0 || height == 0 || width * height > kMaxPixels || !haveSamples) {
    failState(path, "corrupt film state: the header lacks a valid width, height or samples line");
  }
  if (!normalised(state.ranges)) {
    failState(path, "corrupt film state: sample ranges " + rangesText(state.ranges) +
                        " are not sorted and disjoint");
  }
  checkUniqueKeys(state.settings, path);
  checkUniqueKeys(state.info, path);

  // The body and the checksum: lengths first, so that a cut-off file says so.
  const uint64_t available = bytes.size() - pos;
  if (available < dataSize + 8) {
    failState(path, "truncated film state: " + std::to_string(dataSize + 8) +
                        " bytes of data and checksum expected, " + std::to_string(available) +
                        " found");
  }
  if (available > dataSize + 8) {
    failState(path, "corrupt film state: " + std::to_string(available - dataSize - 8) +
                        " unexpected bytes after the data");
  }
  const size_t checked = bytes.size() - 8;
  uint64_t recordedSum = 0;
  for (int b = 0; b < 8; ++b) recordedSum |= uint64_t(bytes[checked + size_t(b)]) << (8 * b);
  if (hashBytes(bytes.data(), checked) != recordedSum) {
    failState(path, "corrupt film state: checksum mismatch (the file was changed or damaged)");
  }
  if (recordedHash != hexHash(settingsHash(state.settings))) {
    failState(path, "corrupt film state: the settings do not match their hash");
  }

  // Every pixel holds one sample (valid or invalid) per sample index outside the open batch.
  if (openRange.count() > 0 && (state.ranges.empty() || openRange.end != state.ranges.back().end ||
                                openRange.first < state.ranges.back().first)) {
    failState(path, "corrupt film state: the open batch " + openRange.toString() +
                        " does not end the sample ranges");
  }
  // An sppm render's film holds its estimate, one sample, after iterations [0, end).
  if (sppmBytes != 0 && (openRange.count() > 0 || state.ranges.size() > 1 ||
                         (!state.ranges.empty() && state.ranges[0].first != 0))) {
    failState(path, "corrupt film state: an sppm state of samples " + rangesText(state.ranges) +
                        (openRange.count() > 0 ? " with an open batch" : ""));
  }
  const uint64_t inFilm = sppmBytes != 0 ? (state.ranges.empty() ? 0u : 1u)
                                         : uint64_t(state.samplesPerPixel()) - openRange.count();
  state.film = Film(int(width), int(height));
  Film& film = state.film;
  Reader in(path, bytes.data() + pos, bytes.data() + checked);
  for (size_t i = 0; i < film.pixelCount(); ++i) {
    film.sampleCount[i] = in.varint();
    film.invalidCount[i] = in.varint();
    if (film.sampleCount[i] + film.invalidCount[i] != inFilm) {
      in.corrupt("pixel " + std::to_string(i) + " holds " +
                 std::to_string(film.sampleCount[i] + film.invalidCount[i]) +
                 " samples, the ranges say " + std::to_string(inFilm));
    }
    for (int c = 0; c < 3; ++c) {
      const unsigned char mask = in.next();
      if (mask >> ExactSum::kLimbs) in.corrupt("a sum is malformed");
      ExactSum& s = film.exact[i][c];
      for (int l = 0; l < ExactSum::kLimbs; ++l) {
        if (mask & (1 << l)) s.limb[l] = in.little(8);
      }
    }
  }
  if (openRange.count() > 0) {
    OpenBatch& open = state.open;
    open.first = openRange.first;
    open.count = openRange.count();
    open.sum.resize(film.pixelCount());
    open.invalid.resize(film.pixelCount());
    for (size_t i = 0; i < film.pixelCount(); ++i) {
      for (int c = 0; c < 3; ++c) open.sum[i][c] = std::bit_cast<float>(uint32_t(in.little(4)));
      open.invalid[i] = uint32_t(in.little(4));
      if (open.invalid[i] > open.count) in.corrupt("an open batch count is out of range");
    }
  }
  if (sppmBytes != 0) {
    state.sppm.resize(film.pixelCount());
    for (SppmPixelRecord& p : state.sppm) {
      float f[8];
      for (float& v : f) v = std::bit_cast<float>(uint32_t(in.little(4)));
      p.radius = f[0];
      p.n = f[1];
      p.tau = glm::vec3(f[2], f[3], f[4]);
      p.ldSum = glm::vec3(f[5], f[6], f[7]);
      const unsigned char invalid = in.next();
      if (invalid > 1) in.corrupt("an sppm pixel's invalid flag is neither 0 nor 1");
      p.invalid = invalid != 0;
    }
  }
  if (!in.atEnd()) in.corrupt("unexpected bytes at the end of the data");
  return state;
}

// ---- Merging --------------------------------------------------------------------------------

void FilmStateMerger::add(NamedFilmState named) {
  FilmState& state = named.state;
  if (!state.sppm.empty()) {
    failState(named.path,
              "holds an sppm render, whose pixels depend on every iteration before: sppm "
              "renders cannot be split or merged (continue one with render --resume)");
  }
  if (seen_.empty()) {
    film_ = Film(state.film.width, state.film.height);
  }
  // Sizes are checked in finish(), with every file's name at hand; only merge what fits.
  if (state.film.width == film_.width && state.film.height == film_.height) {
    film_.merge(state.film);
  }
  const int width = state.film.width, height = state.film.height;
  state.film = Film();
  seen_.push_back(Seen{std::move(named.path), width, height, std::move(state)});
}

FilmState FilmStateMerger::finish() {
  PT_CHECK(!seen_.empty(), "nothing to merge");
  // A fixed order whatever the order of add(): messages and the result do not depend on it.
  auto firstSample = [](const Seen& s) {
    return s.meta.ranges.empty() ? UINT32_MAX : s.meta.ranges.front().first;
  };
  std::sort(seen_.begin(), seen_.end(), [&](const Seen& a, const Seen& b) {
    return std::make_pair(firstSample(a), a.path) < std::make_pair(firstSample(b), b.path);
  });
  const Seen& base = seen_.front();
  for (const Seen& s : seen_) {
    if (s.width != base.width || s.height != base.height) {
      failState(s.path, "is " + std::to_string(s.width) + "x" + std::to_string(s.height) + ", " +
                            base.path.string() + " is " + std::to_string(base.width) + "x" +
                            std::to_string(base.height));
    }
    const std::string diff = settingsDifference(s.meta.settings, base.meta.settings);
    if (!diff.empty()) {
      failState(s.path, "rendered with other settings than " + base.path.string() + ": " + diff);
    }
  }

  // Overlaps: every range with the file it came from, in order of first sample.
  std::vector<std::pair<SampleRange, const fs::path*>> all;
  for (const Seen& s : seen_) {
    for (const SampleRange& r : s.meta.ranges) all.emplace_back(r, &s.path);
  }
  std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) {
    return std::make_pair(a.first.first, *a.second) < std::make_pair(b.first.first, *b.second);
  });
  for (size_t i = 1; i < all.size(); ++i) {
    const auto& [prev, prevPath] = all[i - 1];
    const auto& [cur, curPath] = all[i];
    if (cur.first < prev.end) {
      const SampleRange overlap{cur.first, std::min(prev.end, cur.end)};
      throw InputError(prevPath->string() + " (samples " + prev.toString() + ") and " +
                       curPath->string() + " (samples " + cur.toString() + ") overlap in samples " +
                       overlap.toString());
    }
  }

  FilmState merged;
  merged.settings = base.meta.settings;
  merged.film = std::move(film_);
  std::vector<SampleRange> ranges;
  for (const Seen& s : seen_)
    ranges.insert(ranges.end(), s.meta.ranges.begin(), s.meta.ranges.end());
  merged.ranges = coalesce(ranges);
  // An open batch that ends the merged samples stays open, so that the merged state continues
  // as the one render would; any other is folded (its batch is split for good).
  for (Seen& s : seen_) {
    if (s.meta.open.empty()) continue;
    if (s.meta.ranges.back().end == merged.ranges.back().end) {
      merged.open = std::move(s.meta.open);
    } else {
      s.meta.open.foldInto(merged.film);
    }
  }
  for (const auto& entry : base.meta.info) {
    bool shared = true;
    for (const Seen& s : seen_) {
      const std::string* v = s.meta.infoValue(entry.first);
      shared = shared && v && *v == entry.second;
    }
    if (shared) merged.info.push_back(entry);
  }
  seen_.clear();
  return merged;
}

FilmState mergeFilmStates(std::vector<NamedFilmState> states) {
  FilmStateMerger merger;
  for (NamedFilmState& s : states) merger.add(std::move(s));
  return merger.finish();
}

}  // namespace pt
