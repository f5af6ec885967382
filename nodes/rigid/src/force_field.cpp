#include "vrflow/rigid/force_field.hpp"

#include <cmath>
#include <sstream>

namespace vrflow::rigid {

Result<ForceField> ForceField::parse(std::string_view text) {
  ForceField field;
  std::string all(text);
  std::stringstream terms(all);
  for (std::string termText; std::getline(terms, termText, ';');) {
    std::istringstream in(termText);
    std::string kind;
    if (!(in >> kind)) continue;  // empty term
    FieldTerm term;
    std::vector<double> numbers;
    for (double x; in >> x;) numbers.push_back(x);
    if (!in.eof())
      return makeError("force field term '" + termText + "': not a number after '" + kind + "'");
    auto need = [&](std::size_t lo, std::size_t hi) -> Status {
      if (numbers.size() < lo || numbers.size() > hi)
        return makeError("force field term '" + termText + "': '" + kind + "' takes " +
                         std::to_string(lo) + (lo == hi ? "" : " to " + std::to_string(hi)) +
                         " numbers");
      for (double x : numbers)
        if (!std::isfinite(x))
          return makeError("force field term '" + termText + "': numbers must be finite");
      return {};
    };
    if (kind == "gravity" || kind == "uniform") {
      if (auto s = need(3, 3); !s) return s.error();
      term.kind = kind == "gravity" ? FieldTerm::Kind::Gravity : FieldTerm::Kind::Uniform;
      term.vector = {numbers[0], numbers[1], numbers[2]};
    } else if (kind == "attractor") {
      if (auto s = need(4, 5); !s) return s.error();
      term.kind = FieldTerm::Kind::Attractor;
      term.vector = {numbers[0], numbers[1], numbers[2]};
      term.strength = numbers[3];
      if (numbers.size() == 5) {
        if (!(numbers[4] > 0))
          return makeError("force field term '" + termText + "': RMIN must be positive");
        term.minRadius = numbers[4];
      }
    } else if (kind == "drag") {
      if (auto s = need(1, 2); !s) return s.error();
      if (numbers[0] < 0 || (numbers.size() == 2 && numbers[1] < 0))
        return makeError("force field term '" + termText + "': drag coefficients must be >= 0");
      term.kind = FieldTerm::Kind::Drag;
      term.strength = numbers[0];
      term.angular = numbers.size() == 2 ? numbers[1] : 0.0;
    } else {
      return makeError("force field term '" + termText + "': unknown kind '" + kind +
                       "' (gravity, uniform, attractor, drag)");
    }
    field.add(term);
  }
  return field;
}

msg::ForceEvent ForceField::forceOn(const FieldTarget& target, double dt) const {
  msg::ForceEvent event;
  event.point = target.position;
  event.duration = dt;
  if (!std::isfinite(target.mass)) return event;
  for (const FieldTerm& term : terms_) {
    switch (term.kind) {
      case FieldTerm::Kind::Gravity:
        asEigen(event.force) += asEigen(term.vector) * target.mass;
        break;
      case FieldTerm::Kind::Uniform:
        asEigen(event.force) += asEigen(term.vector);
        break;
      case FieldTerm::Kind::Attractor: {
        const Eigen::Vector3d d = asEigen(term.vector) - asEigen(target.position);
        const double r = std::max(d.norm(), term.minRadius);
        asEigen(event.force) += d * (target.mass * term.strength / (r * r * r));
        break;
      }
      case FieldTerm::Kind::Drag:
        asEigen(event.force) -= asEigen(target.linearVelocity) * term.strength;
        asEigen(event.torque) -= asEigen(target.angularVelocity) * term.angular;
        break;
    }
  }
  return event;
}

Vec3 ForceField::gravity() const {
  Vec3 g{};
  for (const FieldTerm& term : terms_)
    if (term.kind == FieldTerm::Kind::Gravity) asEigen(g) += asEigen(term.vector);
  return g;
}

}  // namespace vrflow::rigid
