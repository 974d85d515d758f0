#include "io/output.hpp"

#include <hdf5.h>

#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <functional>
#include <iterator>
#include <numeric>
#include <stdexcept>
#include <type_traits>

#include "kernels/kernels.hpp"
#include "kernels/measurements.hpp"
#include "simulation/resources.hpp"
#include "laws/strength.hpp"
#include "io/file_io.hpp"
#include "base/version.hpp"

namespace enamel {

Frame captureFrame(const Simulation& sim, double targetDa) {
  Frame f;
  f.targetDa = targetDa;
  f.da = sim.state.crackAdvance;
  f.step = sim.state.step;
  f.time = sim.state.time;
  f.appliedDisplacement = sim.state.appliedDisplacement;
  f.nodeDisplacement.assign(sim.state.q.data(), sim.state.q.data() + sim.state.q.size());
  const int ni = sim.model.numInterfaces();
  f.ifaceDamage.resize(ni);
  f.ifaceState.resize(ni);
  for (int i = 0; i < ni; ++i) {
    const double lm = sim.state.lambdaMax[i];
    f.ifaceDamage[i] = static_cast<float>(cohesive::damage(sim.materials.law, lm));
    f.ifaceState[i] = cohesive::isFailed(sim.materials.law, lm) ? 2 : cohesive::isInelastic(sim.materials.law, lm) ? 1 : 0;
  }
  f.beamBroken = sim.state.beamBroken;
  f.beamStress.resize(sim.model.numBeams());
  for (int e = 0; e < sim.model.numBeams(); ++e)
    f.beamStress[e] = sim.state.beamBroken[e] ? 0.0f
        : static_cast<float>(computeStressOfBeam(sim.model, sim.materials, sim.state.q, e) / sim.params.sigma0());
  return f;
}

const char* resultFileName(RunStatus status) {
  switch (status) {
    case RunStatus::completed: return "result.h5";
    case RunStatus::failed: return "result.failed.h5";
    case RunStatus::running:
    case RunStatus::interrupted: break;
  }
  return "result.partial.h5";
}

std::string resultFileFor(const std::string& dir, RunStatus status) { return dir + "/" + resultFileName(status); }

namespace {
constexpr SealField kSealFields[] = {
    {"magic", "8s", offsetof(ResultSeal, magic), sizeof(ResultSeal::magic)},
    {"format", "I", offsetof(ResultSeal, format), sizeof(ResultSeal::format)},
    {"crc", "I", offsetof(ResultSeal, crc), sizeof(ResultSeal::crc)},
    {"file_bytes", "Q", offsetof(ResultSeal, fileBytes), sizeof(ResultSeal::fileBytes)},
};
// The fields tile the struct without gaps, in order, and their codes have their sizes (Python's struct, "<").
constexpr bool sealFieldsTileTheStruct() {
  std::size_t at = 0;
  for (const SealField& f : kSealFields) {
    const std::size_t codeBytes = f.structCode[0] == 'I' ? 4 : f.structCode[0] == 'Q' ? 8 : f.structCode[0] - '0';
    if (f.offset != at || f.bytes != codeBytes) return false;
    at += f.bytes;
  }
  return at == sizeof(ResultSeal);
}
static_assert(sealFieldsTileTheStruct(), "sealFields must list ResultSeal's fields in order with their sizes");
static_assert(sizeof(ResultSeal) == 24 && sizeof(ResultSeal) <= kUserblockBytes, "the seal fits the user block");
}  // namespace

const std::vector<SealField>& sealFields() {
  static const std::vector<SealField> fields(std::begin(kSealFields), std::end(kSealFields));
  return fields;
}

const std::vector<HistoryColumn>& historyColumns() {
  using M = Measurement;
  static const char* eu = "E_r d^3 (per z-period B = sqrt(3) d)";
  static const std::vector<HistoryColumn> columns = {
      {"step", &M::step, "-"},
      {"time", &M::time, "d/c_r"},
      {"applied_displacement", &M::appliedDisplacement, "d",
       "u_y at the cracked edge of the top row (bottom row: minus this)"},
      {"load", &M::load, "E_r d^2", "generalised force conjugate to applied_displacement"},
      {"J_over_Gamma", &M::J, "Gamma_i", "", true},
      {"da_over_d", &M::crackAdvance, "d"},
      {"kinetic_energy", &M::kinetic, eu},
      {"kinetic_energy_beyond_loading", &M::kineticBeyond, eu,
       "1/2 w^T M w, w = v - (U'/U) q: the kinetic energy left when the quasi-static motion of proportional "
       "loading is taken out (the adaptive loading rate's measure)"},
      {"strain_energy_beams", &M::strainBeams, eu},
      {"strain_energy_interfaces", &M::strainInterfaces, eu},
      {"damping_dissipation", &M::damping, eu},
      {"fracture_dissipation_interfaces", &M::fracture, eu},
      {"fracture_energy_rods", &M::rodFracture, eu},
      {"external_work", &M::external, eu},
      {"energy_balance_error", &M::balanceError, "-",
       "(external work - stored - kinetic - dissipated) / max(|external work|, work_floor), work_floor = 0.1 "
       "Gamma_i B d (this dataset's attribute work_floor, in E_r d^3): meaningful from the first row, where the "
       "work is ~1e-10 of the floor; the relative error of the balance once the work exceeds the floor"},
      {"broken_rod_elements", &M::brokenBeams, "count"},
      {"failed_interfaces", &M::failedInterfaces, "count"},
      {"inelastic_interfaces", &M::inelasticInterfaces, "count"},
      {"kinked_interfaces", &M::kinkedInterfaces, "count",
       "failed interfaces of the crack's cluster (connected to the pre-crack) whose two rods lie on one side of the "
       "crack plane: kinks along the rods, against failed interfaces across the plane"},
      {"rate_multiplier", &M::rateMultiplier, "-",
       "phi: the adaptive loading rate's multiplier of v_app (dU/dt = phi U'(tau); 1 when rate_adapt_max = 1)"},
      {"inelastic_reach_over_d", &M::inelasticReach, "d",
       "largest distance |y - y_crack| from the crack plane of an interface past delta0 or a broken rod element "
       "(midpoints of their nodes' reference positions); h_s/2 is the loaded edge"},
  };
  return columns;
}

RcurveSummary summariseRcurve(const std::vector<double>& da, const std::vector<double>& R) {
  RcurveSummary s;
  if (da.empty()) return s;
  s.R_init = R.front();
  s.daMax = *std::max_element(da.begin(), da.end());
  // R_ss: mean R over the last 20% of the advance reached (R at the largest advance, smoothed).
  double sum = 0;
  int n = 0;
  for (std::size_t i = 0; i < da.size(); ++i)
    if (da[i] >= 0.8 * s.daMax) { sum += R[i]; ++n; }
  s.R_ss = n ? sum / n : NAN;
  // R_m, dR_m: mean and standard deviation of R over 0 < Delta_a/d < 30 (paper, Fig. 9).
  std::vector<double> sel;
  for (std::size_t i = 0; i < da.size(); ++i)
    if (da[i] > 0 && da[i] < 30) sel.push_back(R[i]);
  if (!sel.empty()) {
    s.R_m = std::accumulate(sel.begin(), sel.end(), 0.0) / sel.size();
    double var = 0;
    for (double r : sel) var += (r - s.R_m) * (r - s.R_m);
    s.dR_m = std::sqrt(var / sel.size());
  }
  return s;
}

namespace {

// Peak resident memory of this process (VmHWM of /proc/self/status) in MB; NaN where there is no /proc.
double peakMemoryMB() { return readProcKilobytes("/proc/self/status", "VmHWM") / 1024.0; }

// --- a thin RAII layer over the HDF5 C API ---
struct Handle {
  hid_t id;
  herr_t (*close)(hid_t);
  Handle(hid_t i, herr_t (*c)(hid_t), const std::string& what) : id(i), close(c) {
    if (id < 0) throw std::runtime_error("HDF5: cannot create " + what);
  }
  ~Handle() { if (id >= 0) close(id); }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
};

// Strings are variable-length UTF-8, which h5py reads back as str.
void attr(hid_t obj, const char* name, const std::string& value) {
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose, "string type");
  H5Tset_size(type.id, H5T_VARIABLE);
  H5Tset_cset(type.id, H5T_CSET_UTF8);
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, "scalar space");
  Handle a(H5Acreate2(obj, name, type.id, space.id, H5P_DEFAULT, H5P_DEFAULT), H5Aclose, name);
  const char* text = value.c_str();
  H5Awrite(a.id, type.id, &text);
}
void attr(hid_t obj, const char* name, const char* value) { attr(obj, name, std::string(value)); }
void attr(hid_t obj, const char* name, double value) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, "scalar space");
  Handle a(H5Acreate2(obj, name, H5T_NATIVE_DOUBLE, space.id, H5P_DEFAULT, H5P_DEFAULT), H5Aclose, name);
  H5Awrite(a.id, H5T_NATIVE_DOUBLE, &value);
}
void attr(hid_t obj, const char* name, long value) {
  Handle space(H5Screate(H5S_SCALAR), H5Sclose, "scalar space");
  Handle a(H5Acreate2(obj, name, H5T_NATIVE_LONG, space.id, H5P_DEFAULT, H5P_DEFAULT), H5Aclose, name);
  H5Awrite(a.id, H5T_NATIVE_LONG, &value);
}

template <class T> hid_t nativeType();
template <> hid_t nativeType<double>() { return H5T_NATIVE_DOUBLE; }
template <> hid_t nativeType<float>() { return H5T_NATIVE_FLOAT; }
template <> hid_t nativeType<int>() { return H5T_NATIVE_INT; }
template <> hid_t nativeType<long>() { return H5T_NATIVE_LONG; }
template <> hid_t nativeType<std::uint8_t>() { return H5T_NATIVE_UINT8; }

// A dataset of rows x cols (cols = 1: 1-D) with a `unit` attribute (and an optional description).
template <class T>
void dataset(hid_t group, const char* name, const std::vector<T>& data, std::size_t cols, const std::string& unit,
             const std::string& description = "") {
  const hsize_t rows = cols ? data.size() / cols : 0;
  hsize_t dims[2] = {rows, cols};
  Handle space(H5Screate_simple(cols == 1 ? 1 : 2, dims, nullptr), H5Sclose, name);
  Handle plist(H5Pcreate(H5P_DATASET_CREATE), H5Pclose, "property list");
  if (rows * cols > 4096) {  // compress large arrays
    hsize_t chunk[2] = {std::min<hsize_t>(rows, std::max<hsize_t>(1, 65536 / cols)), cols};
    H5Pset_chunk(plist.id, cols == 1 ? 1 : 2, chunk);
    H5Pset_deflate(plist.id, 4);
  }
  Handle ds(H5Dcreate2(group, name, nativeType<T>(), space.id, H5P_DEFAULT, plist.id, H5P_DEFAULT), H5Dclose, name);
  if (rows > 0) H5Dwrite(ds.id, nativeType<T>(), H5S_ALL, H5S_ALL, H5P_DEFAULT, data.data());
  attr(ds.id, "unit", unit);
  if (!description.empty()) attr(ds.id, "description", description);
}

std::string utcNow() {
  const std::time_t t = std::time(nullptr);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return buf;
}

// One /history dataset: the column's field over all rows, in the field's own type.
void historyDataset(hid_t group, const HistoryColumn& c, const std::vector<Measurement>& h, double Gamma) {
  std::visit([&](auto field) {
    using T = std::remove_reference_t<decltype(Measurement{}.*field)>;
    std::vector<T> values;
    values.reserve(h.size());
    for (const Measurement& r : h) values.push_back(r.*field);
    if (c.perGamma)
      for (T& x : values) x /= Gamma;
    dataset(group, c.name, values, 1, c.unit, c.description);
  }, c.field);
}

// /meta: provenance and run status.
void writeMeta(hid_t file, const Simulation& sim, const RunRecord& rec) {
  const CaseParams& p = sim.params;
  const double Gamma = p.Gamma();
  Handle g(H5Gcreate2(file, "meta", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose, "/meta");
  attr(g.id, "case_toml", p.tomlText);
  attr(g.id, "case_source", p.sourceName);
  attr(g.id, "preset", p.presetName);
  attr(g.id, "solver", "enamel-dem");
  attr(g.id, "solver_version", ENAMEL_VERSION);
  attr(g.id, "git_hash", kGitHash);
  attr(g.id, "integrator", sim.integrator->name());
  attr(g.id, "integrator_details", sim.integrator->describe());
  attr(g.id, "added_rotary_inertia", sim.integrator->addedRotaryInertia());
  attr(g.id, "linear_solver", nameOf(p.linear_solver));
  attr(g.id, "deletion_rule", nameOf(p.deletion_rule));
  attr(g.id, "rod_stress", nameOf(p.rod_stress));
  attr(g.id, "seed", static_cast<long>(p.seed));
  attr(g.id, "strength_generator", kStrengthGenerator);
  attr(g.id, "status", nameOf(rec.status));
  attr(g.id, "stop_reason", rec.stopReason);
  std::string warnings;
  for (const auto& w : rec.warnings) warnings += w + "\n";
  attr(g.id, "warnings", warnings);
  attr(g.id, "wall_time_s", rec.wallSeconds);
  attr(g.id, "max_kinetic_over_strain_while_growing", rec.maxKineticRatio);
  attr(g.id, "max_quasi_static_ratio", rec.maxQuasiStaticRatio);  // the quasi-static warning's (runner.hpp)
  attr(g.id, "steps", rec.steps);
  attr(g.id, "dof", static_cast<long>(sim.model.numDofs()));
  attr(g.id, "threads", static_cast<long>(threadCount()));
  attr(g.id, "peak_memory_mb", peakMemoryMB());
  attr(g.id, "written_utc", utcNow());
  attr(g.id, "units", "normalised: rod spacing d = 1, rod modulus E_r = 1, rod density rho_r = 1 "
                      "(time in d/c_r, c_r = sqrt(E_r/rho_r))");
  attr(g.id, "dt", sim.integrator->timeStep());
  attr(g.id, "E_transverse_over_Er", sim.materials.E_transverse);
  attr(g.id, "c_d_over_cr", sim.materials.c_d);
  attr(g.id, "rayleigh_a", sim.materials.dampA);
  attr(g.id, "rayleigh_b", sim.materials.dampB);
  attr(g.id, "omega_max_element", sim.materials.omegaMaxElement);
  attr(g.id, "v_app", sim.materials.loading.vApp);
  attr(g.id, "Gamma_i", Gamma);
  attr(g.id, "sigma0", p.sigma0());
  attr(g.id, "k", p.k());
  attr(g.id, "softening_over_delta0", p.softening_over_delta0);
  attr(g.id, "shear_strength_ratio", p.shear_strength_ratio);
  attr(g.id, "grip_constraint", nameOf(p.grip_constraint));
  attr(g.id, "grip_profile", nameOf(p.grip_profile));
  attr(g.id, "crisscross_at_tip", nameOf(p.crisscross_at_tip));
  attr(g.id, "a0_effective", sim.model.a0Eff);  // the pre-crack tip (K + 1/4) h_e that Delta_a is measured from
  attr(g.id, "sigma_ru_mean", p.sigma_ru());
  const StaticStart& st = rec.staticStart;
  attr(g.id, "static_start", st.fraction);
  attr(g.id, "static_start_description",
       "static elastic start (case key static_start): the run started at t = static_start_time from the "
       "static elastic solution at applied displacement static_start_U_over_d = static_start x "
       "static_start_Uc_over_d, moving at the loading's quasi-static velocity; static_start_Uc_over_d is the "
       "applied displacement at which the first interface reaches delta0 or the first rod element its "
       "strength (static_start_limited_by), static_start_solve_s the wall time of the static solve, "
       "static_start_mechanism 1 when the elastic stiffness was singular (a part free to move without strain, "
       "e.g. a rod end the pre-crack's cut leaves on one interface, kept where it was). "
       "static_start = 0: the run started from rest (U_c not computed: NaN)");
  attr(g.id, "static_start_Uc_over_d", st.firstDamageDisplacement);
  attr(g.id, "static_start_U_over_d", st.displacement);
  attr(g.id, "static_start_time", st.time);
  attr(g.id, "static_start_limited_by",
       st.fraction > 0 ? (st.limitedByRod ? "rod element strength" : "interface delta0") : "");
  attr(g.id, "static_start_solve_s", st.solveSeconds);
  attr(g.id, "static_start_mechanism", static_cast<long>(st.mechanism));
}

// /rcurve: R over Delta_a and its summary numbers.
void writeRcurve(hid_t file, const Simulation& sim, const RunRecord& rec) {
  const double Gamma = sim.params.Gamma();
  Handle g(H5Gcreate2(file, "rcurve", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose, "/rcurve");
  std::vector<double> R(rec.rcurveJ.size());
  for (std::size_t i = 0; i < R.size(); ++i) R[i] = rec.rcurveJ[i] / Gamma;
  dataset(g.id, "da_over_d", rec.rcurveDa, 1, "d", "crack advance Delta_a / d, one point per advance");
  dataset(g.id, "R_over_Gamma", R, 1, "Gamma_i", "crack resistance J / Gamma_i at that advance");
  const RcurveSummary s = summariseRcurve(rec.rcurveDa, R);
  attr(g.id, "R_init_over_Gamma", s.R_init);
  attr(g.id, "R_ss_over_Gamma", s.R_ss);
  attr(g.id, "R_m_over_Gamma", s.R_m);
  attr(g.id, "dR_m_over_Gamma", s.dR_m);
  attr(g.id, "da_max_over_d", s.daMax);
  attr(g.id, "definitions",
       "R_init: first R with Delta_a > 0; R_ss: mean R over the last 20% of the advance reached; "
       "R_m, dR_m: mean and standard deviation of R over 0 < Delta_a/d < 30");
}

// /geometry: the model, for maps and the VTK export.
void writeGeometry(hid_t file, const Simulation& sim) {
  const CaseParams& p = sim.params;
  const Model& m = sim.model;
  Handle g(H5Gcreate2(file, "geometry", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose, "/geometry");
  std::vector<double> X;
  for (const auto& x : m.X) X.insert(X.end(), {x.x(), x.y(), x.z()});
  dataset(g.id, "node_position", X, 3, "d", "reference positions (x growth, y loading, z stacking)");
  std::vector<int> ply(m.nodePly.begin(), m.nodePly.end());
  dataset(g.id, "node_ply", ply, 1, "-", "0 = ply 1 (+theta), 1 = ply 2 (-theta)");
  dataset(g.id, "node_rod", m.nodeRod, 1, "-");
  dataset(g.id, "node_slice", m.nodeSlice, 1, "-");
  std::vector<int> bn, in;
  for (const auto& b : m.beamNodes) bn.insert(bn.end(), {b[0], b[1]});
  for (const auto& b : m.ifaceNodes) in.insert(in.end(), {b[0], b[1]});
  dataset(g.id, "beam_nodes", bn, 2, "-");
  std::vector<int> span(m.beamSpan.begin(), m.beamSpan.end());
  dataset(g.id, "beam_span", span, 1, "slices",
          "slices a rod element spans: 1, more in a reduced far field (length span h_e / cos theta)");
  dataset(g.id, "beam_strength_over_sigma0", [&] {
    std::vector<double> s(sim.materials.beamStrength);
    for (double& v : s) v /= p.sigma0();
    return s; }(), 1, "sigma0");
  dataset(g.id, "iface_nodes", in, 2, "-", "A, B; B through the z-wrap when iface_zshift = 1");
  std::vector<int> tag(m.ifaceTag.begin(), m.ifaceTag.end()), zs(m.ifaceZShift.begin(), m.ifaceZShift.end());
  dataset(g.id, "iface_tag", tag, 1, "-", "0 ply 1, 1 ply 2, 2 interlayer 1-2, 3 interlayer 2-1 (z-wrap)");
  dataset(g.id, "iface_slice", m.ifaceSlice, 1, "-");
  dataset(g.id, "iface_zshift", zs, 1, "B");
  std::vector<double> area, mid;
  for (int i = 0; i < m.numInterfaces(); ++i) {
    area.push_back(m.ifaceGeom[i].area);
    const Vec3 c = m.X[m.ifaceNodes[i][0]] + m.ifaceGeom[i].armA;
    mid.insert(mid.end(), {c.x(), c.y(), c.z()});
  }
  dataset(g.id, "iface_area", area, 1, "d^2");
  dataset(g.id, "iface_midpoint", mid, 3, "d", "centre of the shared Voronoi edge");
  dataset(g.id, "top_nodes", m.topNodes, 1, "-");
  dataset(g.id, "bottom_nodes", m.bottomNodes, 1, "-");
  attr(g.id, "theta_D_deg", p.theta_D);
  attr(g.id, "w_s", m.w_s);
  attr(g.id, "h_s", m.h_s);
  attr(g.id, "a0", m.a0);
  attr(g.id, "a0_effective", m.a0Eff);
  attr(g.id, "h_e", m.h_e);
  attr(g.id, "z_period_B", m.B);
  attr(g.id, "ply_thickness", m.t);
  attr(g.id, "y_crack_plane", m.yCrack);
  attr(g.id, "x_crisscross", m.xCrisscross);
  attr(g.id, "num_slices", static_cast<long>(m.numSlices));
  attr(g.id, "far_field_slices", static_cast<long>(m.farFieldSlices));
  attr(g.id, "full_band_half_height", m.hasFarField() ? m.fullHalfHeight : 0.5 * m.h_s);
}

// /frames/<n>: the damage snapshots.
void writeFrames(hid_t file, const RunRecord& rec) {
  Handle g(H5Gcreate2(file, "frames", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose, "/frames");
  for (std::size_t i = 0; i < rec.frames.size(); ++i) {
    const Frame& f = rec.frames[i];
    const std::string name = std::to_string(i);
    Handle fg(H5Gcreate2(g.id, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose, "/frames/" + name);
    attr(fg.id, "target_da_over_d", f.targetDa);
    attr(fg.id, "da_over_d", f.da);
    attr(fg.id, "step", f.step);
    attr(fg.id, "time", f.time);
    attr(fg.id, "applied_displacement", f.appliedDisplacement);
    dataset(fg.id, "node_displacement", f.nodeDisplacement, 6, "d (rotations: rad)", "ux uy uz rx ry rz");
    dataset(fg.id, "iface_damage", f.ifaceDamage, 1, "-", "1 - secant stiffness / k");
    dataset(fg.id, "iface_state", f.ifaceState, 1, "-", "0 elastic, 1 inelastic (process zone), 2 failed");
    dataset(fg.id, "beam_broken", f.beamBroken, 1, "-", "1 = rod element deleted");
    dataset(fg.id, "beam_stress", f.beamStress, 1, "sigma0",
            "largest tensile stress of the rod element / sigma0 (the solver's deletion check, "
            "kernels.cpp computeStressOfBeam); 0 for deleted elements (beam_broken)");
  }
}

// The result file's image in memory (HDF5's core driver, no backing store): HDF5 never writes to the disk, so a
// full disk cannot leave it half-closed, and the bytes written are known before they are written. The file is
// created with a user block of kUserblockBytes, which the image leaves out (it begins at the superblock, whose
// base address counts the block): the returned bytes begin with the block, zeros here, for sealImage.
std::string buildImage(const std::string& path, const Simulation& sim, const RunRecord& rec) {
  Handle fcpl(H5Pcreate(H5P_FILE_CREATE), H5Pclose, "file creation property list");
  H5Pset_userblock(fcpl.id, kUserblockBytes);
  Handle fapl(H5Pcreate(H5P_FILE_ACCESS), H5Pclose, "file access property list");
  H5Pset_fapl_core(fapl.id, 1 << 20, 0);
  std::string image;
  {
    Handle file(H5Fcreate(path.c_str(), H5F_ACC_TRUNC, fcpl.id, fapl.id), H5Fclose, "file '" + path + "' in memory");
    writeMeta(file.id, sim, rec);
    writeRcurve(file.id, sim, rec);
    {
      Handle g(H5Gcreate2(file.id, "history", H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), H5Gclose, "/history");
      for (const HistoryColumn& c : historyColumns()) historyDataset(g.id, c, rec.history, sim.params.Gamma());
      Handle balance(H5Dopen2(g.id, "energy_balance_error", H5P_DEFAULT), H5Dclose, "/history/energy_balance_error");
      attr(balance.id, "work_floor", balanceWorkFloor(sim.params.Gamma(), sim.model.B));
    }
    writeGeometry(file.id, sim);
    writeFrames(file.id, rec);
    if (H5Fflush(file.id, H5F_SCOPE_GLOBAL) < 0) throw std::runtime_error("HDF5: cannot flush '" + path + "' in memory");
    const ssize_t n = H5Fget_file_image(file.id, nullptr, 0);
    if (n <= 0) throw std::runtime_error("HDF5: no image of '" + path + "'");
    image.assign(kUserblockBytes + static_cast<std::size_t>(n), '\0');
    if (H5Fget_file_image(file.id, image.data() + kUserblockBytes, static_cast<std::size_t>(n)) != n)
      throw std::runtime_error("HDF5: cannot copy the image of '" + path + "'");
  }
  return image;
}

// The user block: kResultMagic, the format of this block, the CRC-32 of the whole file (its own 4 bytes read as
// zeros) and the file's size (enamel_results/results.py checks them before h5py opens the file).
std::string& sealImage(std::string& image) {
  ResultSeal seal;
  std::memcpy(seal.magic, kResultMagic, sizeof seal.magic);
  seal.fileBytes = image.size();
  std::memcpy(image.data(), &seal, sizeof seal);  // crc = 0
  seal.crc = crc32(image.data(), image.size());
  std::memcpy(image.data(), &seal, sizeof seal);
  return image;
}

}  // namespace

void writeResultFile(const std::string& path, const Simulation& sim, const RunRecord& rec) {
  H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);  // errors become exceptions below, not stderr noise
  std::string image = buildImage(path, sim, rec);
  writeFileAtomically(path, sealImage(image), "result file");
}

}  // namespace enamel
