// pbrt-v4's parameter lists (its ParameterDictionary, paramdict.h): typed lookups that check
// type and count, mark what was read and report the rest. What the values mean is the caller's.
#pragma once

#include <algorithm>
#include <cstddef>
#include <initializer_list>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "scene/json_reader.h"
#include "scene/pbrt/pbrt_parser.h"

namespace pt::pbrt {

using scene_detail::singleQuoted;

class Builder;

// A directive's parameter list with the graphics state's Attribute parameters of the same
// kind behind it (pbrt-v4 looks in the directive's own first). Each read checks the type and
// the count of values and marks the parameter used; the rest are reported as ignored.
class Params {
 public:
  Params(Builder& builder, const Statement& s, const std::vector<Param>* attributes,
         std::string context)
      : builder_(builder), own_(s.params), attributes_(attributes), context_(std::move(context)) {}

  const std::string& context() const { return context_; }

  // The parameter `name` (the last one given, as in pbrt-v4), marked used; or null.
  const Param* find(std::string_view name) const {
    for (auto it = own_.rbegin(); it != own_.rend(); ++it) {
      if (it->name == name) return mark(*it);
    }
    if (attributes_ != nullptr) {
      for (auto it = attributes_->rbegin(); it != attributes_->rend(); ++it) {
        if (it->name == name) return mark(*it);
      }
    }
    return nullptr;
  }

  // The same, failing when its type is none of `types`.
  const Param* find(std::string_view name, std::initializer_list<ParamType> types) const {
    const Param* p = find(name);
    if (p == nullptr) return nullptr;
    if (std::find(types.begin(), types.end(), p->type) == types.end()) {
      std::string expected;
      std::size_t i = 0;
      for (ParamType t : types) {
        if (i > 0) expected += i + 1 == types.size() ? " or " : ", ";
        expected += paramTypeName(t);
        ++i;
      }
      fail(p->location, singleQuoted(p->name) + " of " + context_ + " must be " +
                            (types.size() == 1 ? "a " : "") + expected + ", got " +
                            singleQuoted(p->declaration()));
    }
    return p;
  }

  // Fails unless `p` has exactly `count` values of its type.
  void expectCount(const Param& p, std::size_t count, std::size_t perValue = 1) const {
    const std::size_t n = p.valueCount() / perValue;
    if (n != count) {
      fail(p.location, singleQuoted(p.name) + " of " + context_ + " takes " +
                           std::to_string(count) + (count == 1 ? " value" : " values") + ", got " +
                           std::to_string(n));
    }
  }

  std::optional<double> number(std::string_view name) const {
    const Param* p = find(name, {ParamType::kFloat});
    if (p == nullptr) return std::nullopt;
    expectCount(*p, 1);
    return p->numbers[0];
  }
  std::optional<int> integer(std::string_view name) const {
    const Param* p = find(name, {ParamType::kInteger});
    if (p == nullptr) return std::nullopt;
    expectCount(*p, 1);
    return static_cast<int>(p->numbers[0]);
  }
  std::optional<bool> boolean(std::string_view name) const {
    const Param* p = find(name, {ParamType::kBool});
    if (p == nullptr) return std::nullopt;
    expectCount(*p, 1);
    return static_cast<bool>(p->bools[0]);
  }
  std::optional<std::string> string(std::string_view name) const {
    const Param* p = find(name, {ParamType::kString});
    if (p == nullptr) return std::nullopt;
    expectCount(*p, 1);
    return p->strings[0];
  }

  // A float that must lie in a range; `bounds` names it for the message.
  std::optional<double> bounded(std::string_view name, double lo, bool loOpen, double hi,
                                bool hiOpen, const char* bounds) const {
    const Param* p = find(name, {ParamType::kFloat});
    if (p == nullptr) return std::nullopt;
    expectCount(*p, 1);
    checkBounded(*p, p->numbers[0], lo, loOpen, hi, hiOpen, bounds);
    return p->numbers[0];
  }
  void checkBounded(const Param& p, double v, double lo, bool loOpen, double hi, bool hiOpen,
                    const char* bounds) const {
    // Checked after rounding to float too, as the JSON reader does (1e-50 rounds to 0).
    const double rounded = static_cast<float>(v);
    const bool aboveLo = loOpen ? rounded > lo : rounded >= lo;
    const bool belowHi = hiOpen ? rounded < hi : rounded <= hi;
    if (!(aboveLo && belowHi)) {
      fail(p.location, singleQuoted(p.name) + " of " + context_ + ": expected " + bounds +
                           ", got " + scene_detail::formatNumber(v));
    }
  }

  // Marks every parameter used: for directives ignored as a whole, whose one warning says so.
  void markAllUsed() const {
    for (const Param& p : own_) p.used = true;
  }

  // One warning per parameter (of this context and name) that nothing read.
  void reportUnused() const;

 private:
  const Param* mark(const Param& p) const {
    p.used = true;
    return &p;
  }

  Builder& builder_;
  const std::vector<Param>& own_;
  const std::vector<Param>* attributes_;
  std::string context_;
};

}  // namespace pt::pbrt
