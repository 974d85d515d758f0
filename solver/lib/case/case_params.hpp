// Case-file parameters: the one definition of the case keys (ENAMEL_CASE_KEYS), the plain struct
// whose fields it declares (CaseParams), the table it fills (caseKeys), the built-in presets, and the
// parser that layers
//     key defaults  <  preset  <  case file  <  --set key=value overrides.
// All units are normalised: rod spacing d = 1, rod modulus E_r = 1, rod density rho_r = 1 (docs/model.md).
#pragma once

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "base/choices.hpp"

namespace enamel {

// Kind of value a key holds, and the CaseParams field type it maps to (FieldType<kind, type of the default>::type):
// a Choice key's field is the enum of its default (choices.hpp), any other kind's is KeyValue<kind>::type.
enum class Kind { Real, Integer, Bool, Choice, RealList, Text };
template <Kind> struct KeyValue;
template <> struct KeyValue<Kind::Real> { using type = double; };
template <> struct KeyValue<Kind::Integer> { using type = std::int64_t; };
template <> struct KeyValue<Kind::Bool> { using type = bool; };
template <> struct KeyValue<Kind::RealList> { using type = std::vector<double>; };
template <> struct KeyValue<Kind::Text> { using type = std::string; };
template <Kind K, class Default>
struct FieldType {
    using type = typename KeyValue<K>::type;
};
template <class Default>
struct FieldType<Kind::Choice, Default> {
    static_assert(std::is_enum_v<Default>,
                  "a Choice key's default is an enumerator of its ENAMEL_NAMED_ENUM (choices.hpp), e.g. GripConstraint::uy");
    using type = Default;
};

// Whether a case must state the key.
enum class Need { required, optional };

// ---------------------------------------------------------------------------------------------
// The case keys: the only place where a key, its field, default, range, unit and meaning are written.
// The CaseParams fields, the parser's checks, the presets' and defaults' validation, the effective
// case (tomlText) and `enamel-dem keys` all come from this list, in this order. One row per key:
//   X(name, kind, group, need, default, bounds, min, max, unit, doc)
//     name      TOML key and CaseParams field
//     kind      Real | Integer | Bool | Choice | RealList | Text (Kind)
//     group     physics | numerics (presets may set numerics keys only)
//     need      required (no default: the case must state it; the field starts at 0) | optional
//     default   the field's initial value, which is the key's default; of a Choice key, an enumerator of the
//               key's ENAMEL_NAMED_ENUM in choices.hpp (GripConstraint::uy), whose names are the allowed values
//     bounds    "[]" "[)" "(]" "()": whether min and max themselves are allowed
//     min, max  allowed interval of a Real, an Integer and each element of a RealList; otherwise 0, 0
//     unit      unit or normalisation ("deg", "d", "E_r/(k d)", ...); "-" when dimensionless or not a number
//     doc       meaning; the text before the first ':' is the short name used in messages
// ---------------------------------------------------------------------------------------------
#define ENAMEL_CASE_KEYS(X)                                                                                         \
    /* --- physics --- */                                                                                           \
    X(theta_D, Real, physics, required, 0, "[]", 0, 45, "deg",                                                      \
      "decussation angle: rods at +theta_D in ply 1 and -theta_D in ply 2")                                         \
    X(Er_over_kd, Real, physics, required, 0, "[]", 0.1, 1000, "E_r/(k d)",                                         \
      "rod modulus over interface stiffness: E_r / (k d), k = interface stiffness per area")                        \
    X(sigma_ru_over_sigma0, Real, physics, required, 0, "(]", 0, 1e6, "sigma0",                                     \
      "rod strength: mean tensile strength of a rod element / interface strength sigma0")                           \
    X(cv, Real, physics, optional, 0, "[)", 0, 1, "-",                                                              \
      "strength scatter: coefficient of variation of rod-element strength (normal distribution, "                   \
      "negative draws redrawn)")                                                                                    \
    X(Gamma_k_over_sigma0sq, Real, physics, optional, 9, "[]", 1, 1e4, "sigma0^2/k",                                \
      "interface fracture energy: Gamma_i k / sigma0^2 (>= 1 for a trapezoid law; sets the "                        \
      "fracture length; 9 = identified with the cut tip reading on size-converged specimens, docs/model.md)")     \
    X(softening_over_delta0, Real, physics, optional, 1, "(]", 0, 2e4, "delta0",                                   \
      "interface softening length: (delta_f - delta1)/delta0, the length of the trapezoid's linear drop at "      \
      "fixed Gamma_i (plateau end delta1 = Gamma_i/sigma0 + (delta0 - L)/2); 1 = the symmetric trapezoid, "        \
      "2 Gamma_k_over_sigma0sq - 1 = the triangle (no plateau), the largest allowed")                             \
    X(shear_strength_ratio, Real, physics, optional, 1, "(]", 0, 10, "sigma0",                                    \
      "interface shear strength: beta = shear strength / sigma0 of the mixed-mode law, effective separation "      \
      "lambda = sqrt(<dn>_+^2 + (dt1^2 + dt2^2)/beta^2), traction S(lambda_max) (<dn>_+, dt1, dt2): stiffness k "  \
      "in every mode, shear fracture energy beta^2 Gamma_i; 1 = one law in every mode (docs/model.md)")           \
    X(grip_constraint, Choice, physics, optional, GripConstraint::uy, "[]", 0, 0, "-",                             \
      "grip constraint: of the top and bottom rows' nodes, uy = u_y prescribed (u_x and the rotations free), "    \
      "uxuy = u_y prescribed and u_x = 0 (docs/model.md, Loading)")                                                \
    X(grip_profile, Choice, physics, optional, GripProfile::to_right_edge, "[]", 0, 0, "-",                        \
      "grip profile: u_y = +/-(1 - x/w_s) U on the top/bottom row (to_right_edge: v_app at the cracked edge, 0 "    \
      "at the right edge) or +/-(1 - 2 x/w_s) U (about_centre: the face turned about its centre, v_app at the "    \
      "cracked edge, -v_app at the right edge) (docs/model.md, Loading)")                                          \
    X(delta0_over_d, Real, physics, optional, 0.1, "(]", 0, 1, "d",                                                 \
      "interface elastic separation: delta0 = sigma0 / k. In linear kinematics it only scales forces and "          \
      "displacements, so results depend on it only through the loading rate: what is quasi-static is "              \
      "(v_app/c_d) (h_s / U_c) << 1 with the initiation displacement U_c proportional to delta0 (docs/model.md)")     \
    X(nu_r, Real, physics, optional, 0.3, "[)", 0, 0.5, "-",                                                        \
      "rod Poisson ratio: sets the torsional stiffness G J")                                                        \
    X(section, Choice, physics, optional, SectionShape::hexagon, "[]", 0, 0, "-",                                   \
      "rod cross-section: hexagon = space-filling hexagon of across-flats width d, circle = "                       \
      "circle of diameter d")                                                                                       \
    X(rod_stress, Choice, physics, optional, RodStress::axial_bending, "[]", 0, 0, "-",                           \
      "rod stress definition: of the brittle check, max over both element ends of: axial_bending = N/A + "         \
      "sqrt(My^2 + Mz^2) c/I; axial = N/A; principal = sigma/2 + sqrt((sigma/2)^2 + tau^2), sigma = "              \
      "axial_bending, tau = |T| c/J (torsion only); tension positive, c = d/2")                                    \
    X(seed, Integer, physics, optional, 1, "[]", 0, 2147483647 /* 2^31 - 1 */, "-",                                 \
      "random seed: of the rod-element strengths (mt19937_64 + Box-Muller)")                                        \
    X(rods_breakable, Bool, physics, optional, true, "[]", 0, 0, "-",                                               \
      "rods breakable: false keeps every rod element intact")                                                       \
    X(interfaces_breakable, Bool, physics, optional, true, "[]", 0, 0, "-",                                         \
      "interfaces breakable: false keeps every interface on its elastic branch")                                    \
    X(description, Text, physics, optional, "", "[]", 0, 0, "-",                                                    \
      "description: free text, copied to the output")                                                               \
    /* --- numerics --- */                                                                                          \
    X(w_s_over_d, Real, numerics, optional, 32, "[]", 2, 2000, "d",                                                 \
      "specimen width: along x, the crack growth direction")                                                        \
    X(h_s_over_d, Real, numerics, optional, 16, "[]", 2, 2000, "d",                                                 \
      "specimen height: along y, the loading direction")                                                            \
    X(a0_over_ws, Real, numerics, optional, 0.5, "()", 0, 1, "w_s",                                                 \
      "pre-crack length: a0 / w_s, on the mid-plane y = h_s/2 from the left edge")                                  \
    X(h_e_over_d, Real, numerics, optional, 0.3, "(]", 0, 1, "d",                                                   \
      "slice spacing: distance h_e between discrete yz layers (paper: 0.3 coarse, 0.15 fine; "                      \
      "h_e larger than d is an error)")                                                                             \
    X(crisscross_at_tip, Choice, numerics, optional, CrisscrossAtTip::cut, "[]", 0, 0, "-",                       \
      "crisscross at the tip: the origin of the crisscross lattice, intact = a crisscross point at the pre-crack "  \
      "tip a0_eff = (K + 1/4) h_e, its rods intact (in element [K, K+1]); cut = at a0_eff - h_e/2, its rods cut "   \
      "by the pre-crack (paper Fig. 4: the first intact crisscross ~d/sin(theta_D) ahead) (docs/model.md)")        \
    X(crisscross_phase, Real, numerics, optional, 0, "[)", 0, 1, "d/sin(theta_D)",                                  \
      "crisscross phase: the crisscross points sit at the origin set by crisscross_at_tip plus this fraction of "   \
      "the crisscross spacing d/sin(theta_D), and every d/sin(theta_D) from there (no effect at theta_D = 0)")      \
    X(v_app_over_cd, Real, numerics, optional, 1e-3, "(]", 0, 0.1, "c_d",                                           \
      "loading rate: peak applied velocity at the cracked edge / transverse wave speed c_d")                        \
    X(rate_factor, Real, numerics, optional, 1, "(]", 0, 1e3, "-",                                                  \
      "loading-rate multiplier: v_app = rate_factor x v_app_over_cd x c_d; the pipeline's half-rate "               \
      "twins (paper: 50% slower loading) use 0.5 on top of the preset's rate")                                      \
    X(rate_adapt_max, Real, numerics, optional, 1, "[]", 1, 1000, "-",                                              \
      "adaptive loading rate: the largest multiplier phi it may apply on top of v_app (1 = off); at each "         \
      "history row, with rho = kinetic energy beyond the quasi-static motion of proportional loading (history "  \
      "column kinetic_energy_beyond_loading) / strain energy (rods + interfaces), phi is halved (not below 1) when a "    \
      "rod element was deleted in the interval or rho > rate_adapt_rho_high (0.01), x1.25 (not above this) when "  \
      "rho < a quarter of it (0.0025) and no rod "                                                                 \
      "element was deleted and no more interfaces failed than 4 x the pre-cracked interfaces of one slice, else "   \
      "held; phi "                                                                                                  \
      "ramps linearly to its new value over the next history interval")                                            \
    X(rate_adapt_rule, Choice, numerics, optional, RateAdaptRule::energy, "[]", 0, 0, "-",                         \
      "adaptive loading rate's rule (rate_adapt_max > 1): energy = the rule of rate_adapt_max alone; margin = the " \
      "smaller of that and a forecast's phi: each rod element's stress / strength and each interface's effective " \
      "separation / delta_f extrapolated from its rise since the last history row give the rows at v_app until "  \
      "the first rod break or interface failure, and phi = those rows / "                                          \
      "rate_adapt_horizon within [1, rate_adapt_max]: the rate is 1 over the last rows before a forecast event"    \
      " (docs/solver.md)")                                                                                         \
    X(rate_adapt_horizon, Real, numerics, optional, 10, "[]", 1, 1e4, "history rows at phi = 1",                   \
      "adaptive loading rate, margin rule: phi is the forecast rows to the next failure event / this (within "    \
      "[1, rate_adapt_max]), so the rate falls to 1 as the event comes within this many rows of loading at v_app") \
    X(rate_adapt_rho_high, Real, numerics, optional, 0.01, "(]", 0, 0.05, "-",                                     \
      "adaptive loading rate (either rule): the bound on rho = kinetic energy beyond the loading's motion / "      \
      "strain energy above which phi is halved; phi rises only while rho is below a quarter of it; at most the "  \
      "quasi-static warning bound 0.05 (docs/solver.md, Adaptive loading rate)")                                  \
    X(rate_adapt_velocity, Choice, numerics, optional, RateAdaptVelocity::keep, "[]", 0, 0, "-",                   \
      "adaptive loading rate's velocity at a change of phi: keep = the free nodes keep their velocity (the "       \
      "interior follows the grips' new rate by waves); quasi_static = each time step over which phi changes adds " \
      "(phi_{n+1} - phi_n) U'(tau)/U(tau) q to the free nodes' velocity (the quasi-static motion of proportional " \
      "loading changed with the rate), its kinetic energy booked to the external work (docs/solver.md)")          \
    X(ramp_transits, Real, numerics, optional, 1, "[]", 0, 1e3, "h_s/c_d",                                          \
      "velocity ramp: duration of the smooth ramp from rest, in transit times h_s/c_d")                             \
    X(static_start, Real, numerics, optional, 0, "[)", 0, 1, "-",                                                   \
      "static elastic start: start from the static elastic solution at this fraction of the applied "               \
      "displacement U_c at which the first interface reaches delta0 (or the first rod element its strength, "       \
      "if earlier), moving at the quasi-static velocity of the loading; 0 = start from rest")                       \
    X(far_field_slices, Integer, numerics, optional, 1, "[]", 1, 64, "slices",                                      \
      "reduced far field: outside the full band |y - h_s/2| <= full_half_height_over_d a rod keeps a node in "      \
      "every this many slices (longer rod elements) and the interfaces there are lumped onto those nodes; the run " \
      "stops when the inelastic zone comes within 2 d of the band's edge; 1 = off (docs/solver.md, Reduced far field)") \
    X(full_half_height_over_d, Real, numerics, optional, 0, "[]", 0, 1000, "d",                                     \
      "full band half-height: of the reduced far field (far_field_slices > 1): every slice is kept within this "    \
      "distance of the crack plane; at least 1 d")                                                                  \
    X(far_field_rod_breaks, Choice, numerics, optional, FarFieldRodBreaks::stop, "[]", 0, 0, "-",                  \
      "reduced far field: a rod element deleted within 2 d of the band's edge or beyond it stops the run (stop), "  \
      "or is allowed and recorded as a warning (allow: the far field's element of m slices, with the weakest "      \
      "strength of its parts, breaks whole); interfaces past delta0 there always stop it")                          \
    X(zeta, Real, numerics, optional, 0.2, "[]", 0, 1, "-",                                                         \
      "Rayleigh damping: damping ratio at w_min = pi c_d / h_s (C = a M + b K)")                                    \
    X(dt_factor, Real, numerics, optional, 0.1, "(]", 0, 1, "smallest element period",                              \
      "time step: dt / smallest element period (integrator paper; paper value 0.1)")                                \
    X(integrator, Choice, numerics, optional, IntegratorScheme::paper, "[]", 0, 0, "-",                             \
      "integrator: paper = Newmark beta 0, consistent mass, H = M + dt/2 C factorised (reference); "                \
      "lumped = explicit, lumped mass")                                                                             \
    X(rod_damping, Choice, numerics, optional, RodDamping::implicit, "[]", 0, 0, "-",                              \
      "rods' stiffness damping (integrator lumped): implicit = the full b K of the rods, solved rod by rod "        \
      "at each step (the paper's model); capped = explicit, b' = min(b, damping_cap / omega_max)")                  \
    X(step_rule, Choice, numerics, optional, StepRule::rods, "[]", 0, 0, "-",                                       \
      "time step rule (integrator lumped): rods = dt_factor x the smallest period of the whole lumped system "      \
      "(rotary inertia scaled until rotations stop governing); interfaces = dt_factor x the smallest period of "   \
      "the interfaces on the rods' masses, physical rotary inertia (rod_damping implicit only: the rods' "          \
      "implicit b K keeps their faster modes stable; dt <= 2 b)")                                                   \
    X(damping_cap, Real, numerics, optional, 1, "(]", 0, 2, "-",                                                    \
      "stiffness damping cap (integrator lumped, rod_damping capped): b' = min(b, damping_cap / omega_max), i.e. "  \
      "the stiffness-proportional damping ratio at omega_max is at most damping_cap / 2; a lower cap raises "       \
      "the stable step")                                                                                            \
    X(linear_solver, Choice, numerics, optional, LinearSolver::cholmod, "[]", 0, 0, "-",                            \
      "linear solver: for H = M + dt/2 C (integrator paper): CHOLMOD Cholesky or UMFPACK LU")                       \
    X(deletion_rule, Choice, numerics, optional, DeletionRule::most_overloaded, "[]", 0, 0, "-",                    \
      "rod deletion rule: when several rod elements pass their strength in one step, delete the "                   \
      "most overloaded and re-evaluate, or delete all")                                                             \
    X(stop_da_over_d, Real, numerics, optional, 30, "(]", 0, 1e4, "d",                                              \
      "stop crack advance: the run stops when Delta_a reaches this")                                                \
    X(stop_u_over_d, Real, numerics, optional, 1e3, "(]", 0, 1e6, "d",                                              \
      "stop displacement: the run stops when the applied displacement at the cracked edge "                         \
      "reaches this")                                                                                               \
    X(stop_load_fraction, Real, numerics, optional, 0.05, "[)", 0, 1, "peak load",                               \
      "stop when separated: once the crack has started, the run stops (stop_reason \"separated: ...\") when the "    \
      "grip load stays below this fraction of its peak for stop_load_transits transit times; 0 = off")             \
    X(stop_load_transits, Real, numerics, optional, 1, "(]", 0, 1e3, "h_s/c_d",                                    \
      "stop when separated: how long the load must stay below stop_load_fraction of its peak, in transit times "   \
      "h_s/c_d (checked at history rows)")                                                                          \
    X(max_steps, Integer, numerics, optional, 0, "[]", 0, 4611686018427387904.0 /* 2^62 */, "steps",                \
      "step limit: the run stops after this many time steps; 0 = no limit")                                         \
    X(history_every, Integer, numerics, optional, 0, "[]", 0, 1e9, "steps",                                         \
      "history interval: time steps between /history output rows; 0 = automatic")                                   \
    X(frames_da_over_d, RealList, numerics, optional, (std::vector<double>{5, 15, 30}), "[]", 0, 1e4, "d",          \
      "frames: crack advances Delta_a at which geometry and damage frames are written")                             \
    X(E_transverse_over_Er, Real, numerics, optional, 0, "[]", 0, 10, "E_r",                                        \
      "transverse modulus: sets c_d = sqrt(E_transverse / rho_r); 0 = measure it with a short "                     \
      "elastic run of the model")                                                                                   \
    X(threads, Integer, numerics, optional, 0, "[]", 0, 1024, "-",                                                  \
      "threads: worker threads; 0 = automatic, one per 30k DOF up to all cores (results do not depend on it)")      \
    X(checkpoint_interval_s, Real, numerics, optional, 0, "[]", 0, 1e7, "s (wall clock)",                           \
      "checkpoint interval: wall-clock seconds between checkpoints; 0 = none")

// Names of the built-in presets, in order of size: "ci", "reduced", "converged", "paper".
std::vector<std::string> presetNames();

// One plain field per row of ENAMEL_CASE_KEYS, holding the key's default (required keys: 0) until
// parseCase/loadCase fill it.
// ENAMEL_CASE_FIELD declares the field of one row (tests/cpp/test_case_params.cpp uses it too).
#define ENAMEL_CASE_FIELD(name, kind, group, need, default_, ...) \
    typename ::enamel::FieldType<::enamel::Kind::kind, decltype(default_)>::type name = default_;
struct CaseParams {
    ENAMEL_CASE_KEYS(ENAMEL_CASE_FIELD)

    // --- provenance ---
    std::string sourceName;  // case file path (or the name given to parseCase)
    std::string presetName;  // "" when no preset
    std::string tomlText;    // the effective case (every key) as TOML; parseCase(tomlText) gives it back

    // --- derived quantities (E_r = d = 1) ---
    double k() const { return 1.0 / Er_over_kd; }                  // interface stiffness per area
    double sigma0() const { return delta0_over_d * k(); }          // interface strength = k delta0
    double Gamma() const { return Gamma_k_over_sigma0sq * sigma0() * sigma0() / k(); }  // Gamma_i
    double sigma_ru() const { return sigma_ru_over_sigma0 * sigma0(); }  // mean rod strength
    double a0() const { return a0_over_ws * w_s_over_d; }          // pre-crack length
};

// The CaseParams field of a Choice key, whatever its enum: its value as the index of its name (enumNames) and back.
struct ChoiceField {
    std::size_t (*get)(const CaseParams&);
    void (*set)(CaseParams&, std::size_t);
    bool operator==(const ChoiceField& o) const { return get == o.get && set == o.set; }
};

// The CaseParams member of a key; its alternative is KeyValue<kind>::type (Text: std::string), ChoiceField for
// a Choice key.
using KeyField = std::variant<double CaseParams::*, std::int64_t CaseParams::*, bool CaseParams::*,
                              std::string CaseParams::*, std::vector<double> CaseParams::*, ChoiceField>;

// One row of ENAMEL_CASE_KEYS as data. The default is the field's value in CaseParams{}.
struct KeySpec {
    const char* name;
    Kind kind;
    const char* group;          // "physics" or "numerics"
    bool required;
    double minValue, maxValue;  // Real, Integer, and each element of a RealList
    bool minOpen, maxOpen;      // true: the bound itself is not allowed
    const char* choices;        // Choice: the names of its enum, "a, b, c" (choices.hpp enumNamesText); otherwise ""
    const char* unit;
    const char* doc;
    KeyField field;
};

// Every key, in the order of ENAMEL_CASE_KEYS.
const std::vector<KeySpec>& caseKeys();

// The keys that cannot change a result, only how a run is carried out: a checkpoint written with other values
// of them continues the same run (checkpoint.cpp); every other key decides whether a checkpoint belongs to it.
// history_every is not among them: the adaptive loading rate and the stability checks act at history rows.
inline constexpr const char* kResultNeutralKeys[] = {"threads", "checkpoint_interval_s"};
bool isResultNeutral(const std::string& key);

// Whether a line "key = value" of an effective case (tomlText) gives an optional key its default value, as
// tomlText writes it: a key at its default is the same case as one without the key, so a key added with the
// default that is the result before it leaves the identity of every case that does not set it as it was
// (checkpoint.cpp resultKeys).
bool isDefaultKeyLine(const std::string& line);

// Markdown table of every key: key, group, default, allowed range, unit/normalisation, meaning.
std::string formatKeysMarkdown();

// Error in a case (file, preset, or --set); `exitCode` is one of enamel::exit_code.
// The message is one line naming the source, the key, the value and what is allowed.
struct CaseError : std::runtime_error {
    int exitCode;
    CaseError(int code, const std::string& message) : std::runtime_error(message), exitCode(code) {}
};

// Parse a case given as TOML text. `sourceName` names it in messages; `preset` is one of
// presetNames() or "" for none; `sets` are "key=value" overrides whose values are TOML values
// (a value that is not valid TOML is taken as a string: "integrator=lumped").
// Throws CaseError.
CaseParams parseCase(const std::string& tomlText, const std::string& sourceName,
                     const std::string& preset, const std::vector<std::string>& sets);

// Read the case file at `path` and parseCase it (sourceName = path). Throws CaseError.
CaseParams loadCase(const std::string& path, const std::string& preset,
                    const std::vector<std::string>& sets);

}  // namespace enamel
