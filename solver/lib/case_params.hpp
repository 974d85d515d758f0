// Case-file parameters: the single table of keys (caseKeys), the plain struct they fill (CaseParams),
// the built-in presets, and the parser that layers
//     key defaults  <  preset  <  case file  <  --set key=value overrides.
// All units are normalised: rod spacing d = 1, rod modulus E_r = 1, rod density rho_r = 1 (DESIGN.md 1).
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace enamel {

// Kind of value a key holds, and the CaseParams field type it maps to.
//   Real -> double, Integer -> std::int64_t, Bool -> bool, Choice -> std::string (one of `choices`),
//   RealList -> std::vector<double>, Text -> std::string.
enum class Kind { Real, Integer, Bool, Choice, RealList, Text };

// One case key. The table caseKeys() is the only place keys, defaults, ranges and docs are defined.
struct KeySpec {
    const char* name;        // TOML key, same as the CaseParams field
    Kind kind;
    const char* group;       // "physics" or "numerics" (presets may set numerics keys only)
    bool required;           // no default: the case must state it
    double defaultValue;     // Real, Integer, Bool (0/1); ignored when required
    double minValue, maxValue;  // Real, Integer, and each element of a RealList
    bool minOpen, maxOpen;      // true: the bound itself is not allowed
    const char* choices;     // Choice: "a|b|c"; otherwise ""
    const char* defaultText; // Choice, Text, RealList (a TOML array, e.g. "[5, 15, 30]"); otherwise ""
    const char* unit;        // unit or normalisation ("deg", "d", "E_r/(k d)", ...); "-" when dimensionless or not a number
    const char* doc;         // meaning; the text before the first ':' is the short name used in messages
};

const std::vector<KeySpec>& caseKeys();

// Markdown table of every key: key, group, default, allowed range, unit/normalisation, meaning.
std::string formatKeysMarkdown();

// Names of the built-in presets, in order of size: "ci", "reduced", "paper".
std::vector<std::string> presetNames();

// One plain field per key of caseKeys() (same names). Filled by parseCase/loadCase only: a
// default-constructed CaseParams holds zeros, not the key defaults.
struct CaseParams {
    // --- physics ---
    double theta_D = 0;                // decussation angle (deg)
    double Er_over_kd = 0;             // E_r / (k d)
    double sigma_ru_over_sigma0 = 0;   // mean rod strength / interface strength
    double cv = 0;                     // coefficient of variation of rod-element strength
    double Gamma_k_over_sigma0sq = 0;  // Gamma_i k / sigma0^2
    double delta0_over_d = 0;          // sigma0 / (k d)
    double nu_r = 0;                   // rod Poisson ratio
    std::string section;               // "hexagon" | "circle"
    std::int64_t seed = 0;             // rod-strength random seed
    bool rods_breakable = false;
    bool interfaces_breakable = false;
    std::string description;
    // --- numerics ---
    double w_s_over_d = 0;             // specimen width (x, crack growth) / d
    double h_s_over_d = 0;             // specimen height (y, loading) / d
    double a0_over_ws = 0;             // pre-crack length / w_s
    double h_e_over_d = 0;             // slice spacing / d
    double crisscross_phase = 0;       // first crisscross point ahead of the tip, in d/sin(theta)
    double v_app_over_cd = 0;          // peak applied velocity / c_d
    double rate_factor = 1;            // multiplier on v_app (half-rate twins: 0.5)
    double ramp_transits = 0;          // velocity ramp duration / (h_s/c_d)
    double zeta = 0;                   // Rayleigh damping ratio at w_min = pi c_d / h_s
    double dt_factor = 0;              // dt / smallest element period (integrator "paper")
    double damping_cap = 1;            // lumped: b' omega_max at most this
    std::string integrator;            // "paper" | "lumped"
    std::string linear_solver;         // "cholmod" | "umfpack"
    std::string deletion_rule;         // "most_overloaded" | "all"
    double stop_da_over_d = 0;         // stop at this crack advance / d
    double stop_u_over_d = 0;          // stop at this applied displacement (cracked edge) / d
    std::int64_t max_steps = 0;        // 0 = no limit
    std::int64_t history_every = 0;    // output step interval; 0 = automatic
    std::vector<double> frames_da_over_d;  // crack advances / d at which frames are written
    double E_transverse_over_Er = 0;   // 0 = measure with the model
    std::int64_t threads = 0;          // 0 = all cores
    double checkpoint_interval_s = 0;  // wall-clock seconds between checkpoints; 0 = none

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
