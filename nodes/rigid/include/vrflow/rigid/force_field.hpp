#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "vrflow/base/result.hpp"
#include "vrflow/message/object_type.hpp"  // before values.hpp, or -Wshadow
#include "vrflow/message/values.hpp"
#include "vrflow/rigid/body.hpp"

// The force-field interactor's fields, without messaging. Forces are computed on the state a
// body has now and last one step (duration = dt), applied at its centre of mass.

namespace vrflow::rigid {

/// One field term.
struct FieldTerm {
  enum class Kind { Gravity, Uniform, Attractor, Drag };
  Kind kind = Kind::Gravity;
  Vec3 vector{};  ///< Gravity: acceleration (m/s^2); Uniform: force (N); Attractor: centre
  double strength =
      0.0;               ///< Attractor: mu in a = mu / r^2 towards the centre; Drag: linear (N s/m)
  double angular = 0.0;  ///< Drag: angular drag (N m s)
  double minRadius = 0.1;  ///< Attractor: r is clamped below to this (m)
};

/// What the field needs to know of an object (rigid bodies and point masses alike).
struct FieldTarget {
  double mass = 1.0;  ///< +infinity: the object is kinematic and gets no force
  Vec3 position{};
  Vec3 linearVelocity{};
  Vec3 angularVelocity{};
};

class ForceField {
 public:
  ForceField() = default;
  explicit ForceField(std::vector<FieldTerm> terms) : terms_(std::move(terms)) {}
  /// Parses a field description: terms separated by ';', each `gravity X Y Z`,
  /// `uniform FX FY FZ`, `attractor X Y Z MU [RMIN]` or `drag LINEAR [ANGULAR]`.
  static Result<ForceField> parse(std::string_view text);

  void add(const FieldTerm& term) { terms_.push_back(term); }
  const std::vector<FieldTerm>& terms() const { return terms_; }

  /// The force and torque on `target` (zero for an infinite mass), over `dt`.
  msg::ForceEvent forceOn(const FieldTarget& target, double dt) const;
  /// The sum of the gravity terms (what the contact solver must predict with).
  Vec3 gravity() const;

 private:
  std::vector<FieldTerm> terms_;
};

}  // namespace vrflow::rigid
