#pragma once
// Named enums: an enum class whose enumerators are also its names in files and messages, declared once by
// ENAMEL_NAMED_ENUM. The choices of the case keys are such enums (one per Choice key of ENAMEL_CASE_KEYS,
// case_params.hpp, below): the parser turns the text of a case file into the enumerator of that name, and no
// code after parsing compares strings for a choice. The run status (output.hpp RunStatus) is another.
#include <algorithm>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace enamel {

// Declares `enum class Type { a, b, c };` and enumNamesText(Type) = "a, b, c": the text of the same list, so the
// enumerators (0, 1, 2, ... in order) and their names cannot disagree.
#define ENAMEL_NAMED_ENUM(Type, ...)   \
  enum class Type { __VA_ARGS__ };     \
  constexpr const char* enumNamesText(Type) { return #__VA_ARGS__; }

// "a, b, c" -> {"a", "b", "c"}.
std::vector<std::string> splitEnumNames(std::string_view text);

// The names of a named enum, in the order of its enumerators.
template <class E>
const std::vector<std::string>& enumNames() {
  static const std::vector<std::string> names = splitEnumNames(enumNamesText(E{}));
  return names;
}

// The name of an enumerator ("?" for a value outside the enum: a cast, never a parsed value).
template <class E>
const std::string& nameOf(E e) {
  static const std::string unknown = "?";
  const auto& names = enumNames<E>();
  const auto i = static_cast<std::size_t>(e);
  return i < names.size() ? names[i] : unknown;
}

// The enumerator of a name, or nothing when no enumerator has it.
template <class E>
std::optional<E> enumFromName(std::string_view name) {
  const auto& names = enumNames<E>();
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<E>(i);
  return std::nullopt;
}

// --- the choices of the case keys (the key of each: case_params.hpp; what each value means: its doc there) ---
ENAMEL_NAMED_ENUM(GripConstraint, uy, uxuy)                      // grip_constraint
ENAMEL_NAMED_ENUM(GripProfile, to_right_edge, about_centre)      // grip_profile
ENAMEL_NAMED_ENUM(SectionShape, hexagon, circle)                 // section
ENAMEL_NAMED_ENUM(RodStress, axial_bending, axial, principal)    // rod_stress (beam.hpp rodStressOfRows)
ENAMEL_NAMED_ENUM(CrisscrossAtTip, intact, cut)                  // crisscross_at_tip
ENAMEL_NAMED_ENUM(FarFieldRodBreaks, stop, allow)                // far_field_rod_breaks
ENAMEL_NAMED_ENUM(IntegratorScheme, paper, lumped)               // integrator (integrators/registry.cpp)
ENAMEL_NAMED_ENUM(LinearSolver, cholmod, umfpack)                // linear_solver
ENAMEL_NAMED_ENUM(RodDamping, implicit, capped)                  // rod_damping (integrators/rod_damping.hpp)
ENAMEL_NAMED_ENUM(StepRule, rods, interfaces)                    // step_rule (integrators/lumped.cpp)
ENAMEL_NAMED_ENUM(DeletionRule, most_overloaded, all)            // deletion_rule
ENAMEL_NAMED_ENUM(RateAdaptRule, energy, margin)                 // rate_adapt_rule (loading_rate.hpp)
ENAMEL_NAMED_ENUM(RateAdaptVelocity, keep, quasi_static)         // rate_adapt_velocity (loading_rate.hpp)

}  // namespace enamel
