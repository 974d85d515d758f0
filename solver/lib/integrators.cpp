#include "integrators.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#if defined(_OPENMP)
#include <omp.h>
#endif

#include <Eigen/CholmodSupport>
#include <Eigen/UmfPackSupport>

#include "kernels.hpp"
#include "node_blocks.hpp"
#include "loading_rate.hpp"

namespace enamel {

namespace {

// Rows `rows` of a sparse matrix, as a (rows.size() x n) sparse matrix.
SpMat selectRows(const SpMat& A, const std::vector<int>& rows) {
  std::vector<int> rowIndex(A.rows(), -1);
  for (std::size_t i = 0; i < rows.size(); ++i) rowIndex[rows[i]] = static_cast<int>(i);
  std::vector<Eigen::Triplet<double>> trip;
  for (int c = 0; c < A.outerSize(); ++c)
    for (SpMat::InnerIterator it(A, c); it; ++it)
      if (rowIndex[it.row()] >= 0) trip.emplace_back(rowIndex[it.row()], c, it.value());
  SpMat S(static_cast<Eigen::Index>(rows.size()), A.cols());
  S.setFromTriplets(trip.begin(), trip.end());
  return S;
}

// --- pieces of a step that both schemes use -------------------------------------------------------------
// t_{n+1} = t_n + dt, n + 1, and the loading clock tau_{n+1} (loading_rate.hpp)
void advanceClock(const Loading& loading, State& s, double dt) {
  s.time += dt;
  ++s.step;
  advanceLoadingClock(loading, dt, s);
}

// The prescribed DOFs' entries of a vector indexed by DOF.
void gatherGrips(const Operators& ops, const VecX& x, VecX& atGrips) {
  atGrips.resize(static_cast<Eigen::Index>(ops.prescribedDofs.size()));
  for (std::size_t i = 0; i < ops.prescribedDofs.size(); ++i) atGrips[i] = x[ops.prescribedDofs[i]];
}

// P = sum_p R_p v_p: the power of the grips (summed in the order of the prescribed DOFs)
double computeGripPower(const VecX& reaction, const VecX& gripVelocity) {
  double power = 0;
  for (Eigen::Index i = 0; i < reaction.size(); ++i) power += reaction[i] * gripVelocity[i];
  return power;
}

// W_ext += dt/2 (P_prev + P): trapezoid rule over the interval that ends where P was taken (none when
// `intervalEnds` is false: the first reactions of `lumped`, at t_0); P is kept for the next interval.
void addWorkOfGrips(State& s, double power, double dt, bool intervalEnds = true) {
  if (intervalEnds) s.externalWork += 0.5 * dt * (s.lastExternalPower + power);
  s.lastExternalPower = power;
}

// The paper's scheme (eq. 12-15): Newmark beta = 0 with consistent mass and Rayleigh damping. One step:
//   w       = v_n + dt/2 a_n                              (predicted velocity, where the damping acts)
//   q_{n+1} = q_n + dt v_n + dt^2/2 a_n                   (positions)
//   q, v, a of the grips at t_{n+1}                       (boundary conditions)
//   f_iface(q_{n+1}), K q_{n+1}, C w = a M w + b K w      (forces for interfaces, for beams)
//   H a_{n+1} = -f_iface - K q_{n+1} - C w,  H = M + dt/2 C   (accelerations)
//   v_{n+1} = w + dt/2 a_{n+1}                            (velocities)
//   W_damp += dt w . C w                                  (damping work)
//   R_p = (M a + C v + K q + f_iface)_p at t_{n+1}; W_ext += dt/2 (P_n + P_{n+1})  (reactions, grips' work)
// H is factorised once (CHOLMOD Cholesky, or UMFPACK LU) and re-factorised after rod deletions. Prescribed
// DOFs are eliminated: H_ff a_f = r_f - H_fp a_p.
class PaperIntegrator : public Integrator {
 public:
  PaperIntegrator(const CaseParams& p, const Materials& mat, const Operators& ops)
      : useUmfpack_(p.linear_solver == "umfpack"), dampA_(mat.dampA), dampB_(mat.dampB) {
    dt_ = p.dt_factor * 2.0 * M_PI / mat.omegaMaxElement;
    const double limit = 2.0 / mat.omegaMaxElement;
    // Interfaces add stiffness (about k A_i per node against E A / L for the beams): keep 5% margin.
    if (dt_ > 0.95 * limit) {
      std::ostringstream msg;
      msg << "time step dt = " << dt_ << " (dt_factor " << p.dt_factor
          << " x smallest element period) is above the stable limit 0.95 x 2/omega_max = " << 0.95 * limit
          << " (omega_max = " << mat.omegaMaxElement << "): use dt_factor <= "
          << 0.95 * limit * mat.omegaMaxElement / (2 * M_PI);
      throw IntegratorError(msg.str());
    }
    factorise(ops, true);
  }

  std::string name() const override { return "paper"; }
  double timeStep() const override { return dt_; }

  void advance(const Model& m, const Materials& mat, const Operators& ops, State& s) override {
    predictVelocities(s);
    advancePositions(s);
    advanceClock(mat.loading, s, dt_);
    applyBoundaryConditions(ops, mat.loading, dt_, s);
    s.failedInterfaces = computeForcesForInterfaces(m, mat.law, ops, s.q, s.lambdaMax, true, fI_);
    computeForcesForBeams(ops, s);
    solveAccelerations(ops, s);
    advanceVelocities(ops, s);
    addDampingWork(s);
    computeReactions(ops, s);
    gatherGrips(ops, s.v, vGrip_);
    addWorkOfGrips(s, computeGripPower(s.reaction, vGrip_), dt_);
  }

  void initialise(const Model& m, const Materials& mat, const Operators& ops, State& s) override {
    applyBoundaryConditions(ops, mat.loading, dt_, s);
    computeForcesForInterfaces(m, mat.law, ops, s.q, s.lambdaMax, false, fI_);
    r_ = -fI_ - ops.K * s.q - dampB_ * (ops.K * s.v) - dampA_ * (ops.M * s.v);
    solveAccelerations(ops, s);
  }

  void updateOperators(const Operators& ops) override { factorise(ops, false); }

  double kineticEnergy(const Operators& ops, const State& s) const override { return 0.5 * s.v.dot(ops.M * s.v); }
  double kineticEnergyBeyond(const Operators& ops, const State& s, double rate) const override {
    const VecX w = s.v - rate * s.q;
    return 0.5 * w.dot(ops.M * w);
  }

 private:
  // w = v_n + dt/2 a_n
  void predictVelocities(const State& s) { w_ = s.v + 0.5 * dt_ * s.a; }

  // q_{n+1} = q_n + dt v_n + dt^2/2 a_n
  void advancePositions(State& s) const { s.q += dt_ * s.v + 0.5 * dt_ * dt_ * s.a; }

  // K q_{n+1}, and the damping force's parts K w, M w; r = -f_iface - K q - b K w - a M w
  void computeForcesForBeams(const Operators& ops, const State& s) {
    Kq_ = ops.K * s.q;
    Kw_ = ops.K * w_;
    Mw_ = ops.M * w_;
    r_ = -fI_ - Kq_ - dampB_ * Kw_ - dampA_ * Mw_;
  }

  // H_ff a_f = r_f - H_fp a_p (a_p: the grips' accelerations, already prescribed)
  void solveAccelerations(const Operators& ops, State& s) {
    gatherGrips(ops, s.a, aGrip_);
    rf_.resize(static_cast<Eigen::Index>(ops.freeDofs.size()));
    for (std::size_t i = 0; i < ops.freeDofs.size(); ++i) rf_[i] = r_[ops.freeDofs[i]];
    rf_ -= Hfp_ * aGrip_;
    af_ = useUmfpack_ ? VecX(lu_.solve(rf_)) : VecX(chol_.solve(rf_));
    for (std::size_t i = 0; i < ops.freeDofs.size(); ++i) s.a[ops.freeDofs[i]] = af_[i];
  }

  // v_{n+1} = w + dt/2 a_{n+1} (free DOFs; the grips' v is prescribed)
  void advanceVelocities(const Operators& ops, State& s) const {
    for (std::size_t i = 0; i < ops.freeDofs.size(); ++i) {
      const int dof = ops.freeDofs[i];
      s.v[dof] = w_[dof] + 0.5 * dt_ * af_[i];
    }
  }

  // W_damp += dt w . (a M w + b K w): the damping force's work over the step, at the mid-step velocity w
  void addDampingWork(State& s) const { s.dampingWork += dt_ * w_.dot(dampA_ * Mw_ + dampB_ * Kw_); }

  // R_p = (M a + a M v + b K v + K q + f_iface)_p: the force the grips apply, at t_{n+1}
  void computeReactions(const Operators& ops, State& s) const {
    s.reaction = Mp_ * s.a + dampA_ * (Mp_ * s.v) + dampB_ * (Kp_ * s.v);
    for (std::size_t i = 0; i < ops.prescribedDofs.size(); ++i)
      s.reaction[i] += Kq_[ops.prescribedDofs[i]] + fI_[ops.prescribedDofs[i]];
  }

  // H = (1 + dt/2 a) M + dt/2 b K, split into free and prescribed parts; H_ff factorised
  void factorise(const Operators& ops, bool first) {
    const SpMat H = (1.0 + 0.5 * dt_ * dampA_) * ops.M + (0.5 * dt_ * dampB_) * ops.K;
    std::vector<Eigen::Triplet<double>> tff, tfp;
    std::vector<int> presIndex(H.rows(), -1);
    for (std::size_t i = 0; i < ops.prescribedDofs.size(); ++i) presIndex[ops.prescribedDofs[i]] = static_cast<int>(i);
    for (int c = 0; c < H.outerSize(); ++c)
      for (SpMat::InnerIterator it(H, c); it; ++it) {
        const int fr = ops.dofToFree[it.row()];
        if (fr < 0) continue;
        const int fc = ops.dofToFree[c];
        if (fc >= 0) tff.emplace_back(fr, fc, it.value());
        else tfp.emplace_back(fr, presIndex[c], it.value());
      }
    const Eigen::Index nf = static_cast<Eigen::Index>(ops.freeDofs.size());
    SpMat Hff(nf, nf);
    Hff.setFromTriplets(tff.begin(), tff.end());
    Hfp_.resize(nf, static_cast<Eigen::Index>(ops.prescribedDofs.size()));
    Hfp_.setFromTriplets(tfp.begin(), tfp.end());
    bool ok;
    if (useUmfpack_) {
      if (first) lu_.analyzePattern(Hff);
      lu_.factorize(Hff);
      ok = lu_.info() == Eigen::Success;
    } else {
      if (first) chol_.analyzePattern(Hff);
      chol_.factorize(Hff);
      ok = chol_.info() == Eigen::Success;
    }
    if (!ok) throw SolverError("factorisation of H = M + dt/2 C failed (matrix not positive definite?)");
    Mp_ = selectRows(ops.M, ops.prescribedDofs);
    Kp_ = selectRows(ops.K, ops.prescribedDofs);
  }

  double dt_ = 0;
  bool useUmfpack_ = false;
  double dampA_ = 0, dampB_ = 0;  // Rayleigh C = a M + b K
  Eigen::CholmodSupernodalLLT<SpMat> chol_;
  Eigen::UmfPackLU<SpMat> lu_;
  SpMat Hfp_, Mp_, Kp_;
  VecX w_, fI_, Kq_, Kw_, Mw_, r_, rf_, af_, aGrip_, vGrip_;
};

// Rotary-inertia scale for the lumped element (docs/solver.md): with physical rotary inertia the short
// beam's rotation modes govern; scaling the rotary inertia up lowers them until the element's highest
// frequency is set by its translational masses (axial 2c/L, or the bending mode with rotations frozen,
// sqrt(48 E I / (rho A L^4))), which no rotary scaling can lower. Returns the smallest scale >= 1 within 5% of
// that floor. Rotary inertia does not enter a quasi-static solution; the added inertia is reported.
double rotaryScaleForTranslationalLimit(const beam::Section& s, double L) {
  const double floor = beam::maxFrequency(s, L, beam::MassKind::Lumped, 1e8);
  auto governs = [&](double scale) { return beam::maxFrequency(s, L, beam::MassKind::Lumped, scale) > 1.05 * floor; };
  double lo = 1.0, hi = 1.0;
  if (!governs(lo)) return lo;
  while (governs(hi)) hi *= 2.0;
  for (int it = 0; it < 40; ++it) {
    const double mid = std::sqrt(lo * hi);
    (governs(mid) ? lo : hi) = mid;
  }
  return hi;
}

// Largest frequency of the assembled undamped system M^-1 (K + K_iface) with a diagonal mass, by power
// iteration (prescribed DOFs held). Interfaces enter through their elastic force at a small amplitude (the
// law is linear below delta0, contact included), never assembled.
double estimateOmegaMax(const CaseParams& p, const Model& m, const cohesive::Law& law, const Operators& ops,
                        const VecX& invMass) {
  const int n = static_cast<int>(invMass.size());
  VecX x = VecX::Zero(n), f(n), y(n);
  // A fixed start vector, drawn node by node along each rod (rod by rod), so that neither the estimate nor
  // the time step depends on how the model numbers its nodes.
  std::vector<int> alongRods(m.numNodes());
  for (int i = 0; i < m.numNodes(); ++i) alongRods[i] = i;
  std::sort(alongRods.begin(), alongRods.end(), [&](int a, int b) {
    return std::make_pair(m.nodeRod[a], m.nodeSlice[a]) < std::make_pair(m.nodeRod[b], m.nodeSlice[b]);
  });
  std::uint64_t seed = 12345;
  for (int node : alongRods)
    for (int dof = 6 * node; dof < 6 * node + 6; ++dof) {
      if (ops.dofToFree[dof] < 0) continue;
      seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
      x[dof] = static_cast<double>(seed >> 11) / 9007199254740992.0 - 0.5;
    }
  // the case's delta0 (not the law's: unbreakable interfaces have an infinite one)
  const double amplitude = 1e-3 * p.sigma0() / p.k();
  std::vector<double> lambdaMax(m.numInterfaces(), 0.0);  // undamaged
  double lambda = 0;
  for (int it = 0; it < 300; ++it) {
    x *= amplitude / x.cwiseAbs().maxCoeff();
    computeForcesForInterfaces(m, law, ops, x, lambdaMax, false, f);
    y = invMass.cwiseProduct(ops.K * x + f);
    for (int dof : ops.prescribedDofs) y[dof] = 0;
    const double next = x.dot(y.cwiseQuotient(invMass)) / x.dot(x.cwiseQuotient(invMass));
    x = y;
    if (it > 20 && std::abs(next - lambda) < 1e-6 * next) { lambda = next; break; }
    lambda = next;
  }
  return std::sqrt(std::max(lambda, 0.0));
}

// K in node blocks for the lumped step: node_blocks.hpp.

// The wrench of a slice whose interfaces the law did not see (all elastic: their forces are in K_I q).
alignas(16) constexpr double kNoWrench[6] = {0, 0, 0, 0, 0, 0};

// The lumped step's node rows are compiled three times where GCC builds for x86-64 (function multi-versioning),
// and the loader picks the one the CPU runs: x86-64-v4 (AVX-512: 32 vector registers, broadcasts folded into the
// multiply-adds), x86-64-v3 (AVX2, FMA) or the default x86-64. The v4 and v3 copies give the same bits; the default
// differs from them by round-off (FMA rounds a * b + c once); one CPU gives the same bits at any thread count.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#define ENAMEL_HAS_CPU_CLONES 1
#define ENAMEL_CPU_CLONES [[gnu::target_clones("arch=x86-64-v4", "arch=x86-64-v3", "default")]]
#else
#define ENAMEL_HAS_CPU_CLONES 0
#define ENAMEL_CPU_CLONES
#endif

// Fast scheme `lumped` (ours, docs/solver.md): explicit central differences with a diagonal mass.
//   M: lumped rod mass, translations rho A L / 2 per element end; rotations an isotropic rotary inertia
//      alpha rho Ip L / 2 per element end, alpha the smallest scale at which rotations stop governing.
//   C = a M + b' K with b' = min(b, c/omega_max), c = damping_cap (default 1: the stiffness part's damping
//      ratio at omega_max is at most 1/2; an explicit stiffness damping above that would need a far smaller
//      step, and a lower cap allows a larger one).
//   dt = dt_factor x 2 pi / omega_max (the smallest period of this system), refused above the limit
//   2 / omega_max (sqrt(1 + xi^2) - xi), xi = b' omega_max / 2.
// One step, from q_n and the half-step velocity v_{n-1/2} (State::vHalf), forces first:
//   f_iface(q_n) = K_I q_n + f_corr, K q_n, K v_{n-1/2}  (forces for interfaces, for beams: every interface's
//                                                          elastic force is linear, K_I q_n (K_I: the elastic
//                                                          interfaces' stiffness, elasticInterfaceBlocks); the
//                                                          law sees only those that could leave the elastic
//                                                          track (InterfaceSchedule, kernels.hpp), and f_corr is
//                                                          the law's force minus the elastic one of those off
//                                                          it; the interfaces' history is updated here, at q_n)
//   v_{n+1/2} = [(1 - a dt/2) v_{n-1/2} + dt M^-1 (-K q_n - f_iface - b' K v_{n-1/2})] / (1 + a dt/2)
//   v_{n+1/2} of the grips = shape V(t_n + dt/2)          (velocities, boundary condition on them)
//   R_p = (K q + f_iface + b' K v_{n-1/2} + M (a_p + a v_p))_p at t_n, with the grips' a_p and v_p by central
//         differences of v_{n-1/2} and v_{n+1/2}; W_ext += dt/2 (P_{n-1} + P_n)   (reactions, grips' work)
//   W_damp += dt v_{n+1/2} . (a M v_{n+1/2} + b' K v_{n-1/2})   (damping work: the step's displacement
//                                                          against the damping force, its stiffness part
//                                                          as applied, at the lagged velocity)
//   q_{n+1} = q_n + dt v_{n+1/2};  q of the grips = shape U(t_{n+1})   (positions, boundary condition)
class LumpedIntegrator : public Integrator {
 public:
  LumpedIntegrator(const CaseParams& p, const Model& m, const Materials& mat, const Operators& ops)
      : dampA_(mat.dampA) {
    const double L = m.beamLength;
    rotaryScale_ = rotaryScaleForTranslationalLimit(mat.section, L);
    Kblocks_ = toNodeBlocks(SpMatRow(ops.K));
    KI_ = elasticInterfaceBlocks(m, mat.law, ops);
    if (cpuHasAvx512()) KIocts_ = octsOfSplit(KI_.split);  // empty where K_I is not split
    // per element end, of an element spanning `span` slices (1 but in a reduced far field)
    auto mt = [&](int span) { return 0.5 * mat.section.rho * mat.section.A * (span * L); };
    auto jr = [&](int span) { return rotaryScale_ * 0.5 * mat.section.rho * mat.section.Ip * (span * L); };
    mass_ = VecX::Zero(m.numDofs());
    auto addElementMass = [&](int a, int b, int span) {
      const double t = mt(span), r = jr(span);
      for (int node : {a, b})
        for (int k = 0; k < 3; ++k) { mass_[6 * node + k] += t; mass_[6 * node + 3 + k] += r; }
    };
    for (int e = 0; e < m.numBeams(); ++e) addElementMass(m.beamNodes[e][0], m.beamNodes[e][1], m.beamSpan[e]);
    for (const auto& ab : ops.cutBeamNodes) addElementMass(ab[0], ab[1], 1);  // cut by the pre-crack: mass stays
    for (int i = 0; i < mass_.size(); ++i)
      if (mass_[i] <= 0) throw IntegratorError("node without rod mass: the lumped integrator needs every node on a rod");
    invMass_ = mass_.cwiseInverse();
    classifyNodeMasses(m.numNodes());
    sliceReach_ = std::max(sliceReach(m, Kblocks_), sliceReach(m, KI_));
    gripOfDof_.assign(m.numDofs(), -1);
    nodeHasGrip_.assign(m.numNodes(), 0);
    for (std::size_t i = 0; i < ops.prescribedDofs.size(); ++i) {
      gripOfDof_[ops.prescribedDofs[i]] = static_cast<int>(i);
      nodeHasGrip_[ops.prescribedDofs[i] / 6] = 1;
    }
    gripResidual_ = VecX::Zero(static_cast<Eigen::Index>(ops.prescribedDofs.size()));
    for (double shape : ops.prescribedShape) largestShape_ = std::max(largestShape_, std::abs(shape));
    omegaMax_ = estimateOmegaMax(p, m, mat.law, ops, invMass_);
    bEff_ = std::min(mat.dampB, p.damping_cap / omegaMax_);
    dt_ = p.dt_factor * 2.0 * M_PI / omegaMax_;
    const double xi = 0.5 * bEff_ * omegaMax_ + 0.5 * mat.dampA / omegaMax_;
    const double limit = 2.0 / omegaMax_ * (std::sqrt(1.0 + xi * xi) - xi);
    if (dt_ > 0.95 * limit) {
      std::ostringstream msg;
      msg << "time step dt = " << dt_ << " (dt_factor " << p.dt_factor
          << " x smallest period 2 pi/omega_max of the lumped system) is above the stable limit 0.95 x "
          << limit << " (omega_max = " << omegaMax_ << ", damping ratio there " << xi
          << "): use dt_factor <= " << 0.95 * limit * omegaMax_ / (2 * M_PI);
      throw IntegratorError(msg.str());
    }
  }

  std::string name() const override { return "lumped"; }
  double timeStep() const override { return dt_; }
  bool usesConsistentMass() const override { return false; }
  bool usesHalfStepVelocity() const override { return true; }
  double addedRotaryInertia() const override { return rotaryScale_ - 1.0; }
  std::string describe() const override {
    std::ostringstream o;
    o << "lumped mass, rotary inertia x " << rotaryScale_ << ", omega_max " << omegaMax_
      << ", stiffness damping b' " << bEff_ << ", " << Kblocks_.values.size() / 36
      << " distinct 6x6 stiffness blocks" << (Kblocks_.split.empty() ? "" : " (in-plane and out-of-plane DOFs uncoupled: 18 entries each)")
      << ", elastic interfaces in " << KI_.values.size() / 36 << " distinct 6x6 blocks (18 entries each), node rows "
      << nodeRowsTarget();
    return o.str();
  }

  void advance(const Model& m, const Materials& mat, const Operators& ops, State& s) override {
    gatherGrips(ops, s.vHalf, vGripBefore_);  // v_{n-1/2} of the grips, for their reactions
    s.failedInterfaces = computeForcesAndAdvanceVelocities(m, mat, ops, s);
    computeReactions(ops, s);
    addWorkOfGrips(s, computeGripPower(s.reaction, vGrip_), dt_, s.step > 0);
    addDampingWork(s);
    const PositionMove move = moveOfStep();
    advanceClock(mat.loading, s, dt_);
    const double Ubefore = s.appliedDisplacement;
    prescribeDisplacements(ops, mat.loading, s);
    moveBound_ = boundOfMove(move, Ubefore, s.appliedDisplacement);
    largestValue_ = std::max(move.largestValue, largestShape_ * std::abs(s.appliedDisplacement));  // >= max |q_{n+1}|
  }

  double lastStepMoveBound() const override { return moveBound_; }
  const InterfaceSchedule* interfaceSchedule() const override { return &ifaceSchedule_; }

  void initialise(const Model& m, const Materials& mat, const Operators& ops, State& s) override {
    moveBound_ = INFINITY;  // q set from outside the step (the static start): the interface schedule starts afresh
    applyBoundaryConditions(ops, mat.loading, dt_, s);
    computeForcesForInterfaces(m, mat.law, ops, s.q, s.lambdaMax, false, fI_);
    const VecX acc = -invMass_.cwiseProduct(fI_ + ops.K * s.q + bEff_ * (ops.K * s.v)) - dampA_ * s.v;
    s.vHalf = s.v;
    for (int dof : ops.freeDofs) s.vHalf[dof] -= 0.5 * dt_ * acc[dof];
    prescribeVelocities(ops, computeGripVelocity(mat.loading, s, -0.5 * dt_, dt_), s.vHalf);
  }

  void updateOperators(const Operators& ops) override {  // the lumped mass stays; only K changed
    Kblocks_ = toNodeBlocks(SpMatRow(ops.K));
  }

  double kineticEnergy(const Operators&, const State& s) const override {
    return 0.5 * s.vHalf.dot(mass_.cwiseProduct(s.vHalf));
  }
  double kineticEnergyBeyond(const Operators&, const State& s, double rate) const override {
    const VecX w = s.vHalf - rate * s.q;
    return 0.5 * w.dot(mass_.cwiseProduct(w));
  }

 private:
  // The constants of a step's velocity update.
  struct NodeStep {
    double keep, scale, dt, b, Vgrip;  // 1 - a dt/2, 1 + a dt/2, dt, b', V(t_n + dt/2)
  };

  // Forces, then velocities, slice by slice in one pass over the model (its slices in parallel; within a
  // slice in a fixed order, so nothing depends on the thread count). Per slice:
  //   the wrench W of its interfaces on its nodes beyond their elastic force: the law's (opening, law, force
  //     on B) of those the schedule makes due (InterfaceSchedule, kernels.hpp), their history updated at q_n,
  //     less the elastic force of those off the elastic branch
  //   per node: K_I q_n (its block row; all the slice's nodes first), then (advanceNode) K q_n and K v_{n-1/2}
  //     (its block rows), r = K q + K_I q - W + b' K v,
  //     v_{n+1/2} = [(1 - a dt/2) v_{n-1/2} - dt M^-1 r] / (1 + a dt/2), and for the grips
  //     v_{n+1/2} = shape V(t_n + dt/2) and r kept for their reactions
  //   the slice's share of the damping work's sums v.Mv and v.Kv_{n-1/2}
  //   q_{n+1} = q_n + dt v_{n+1/2}, and the slice's share of its maxima max |dt v|, max |q_{n+1}|
  // v_{n+1/2} and q_{n+1} replace v_{n-1/2} and q_n in place once no slice still to come reads them
  // (SliceOutputs: a slice's rows reach sliceReach_ slices either side; each thread takes one run of
  // consecutive slices, and those its neighbours read wait for the end of the pass). Returns the number of
  // failed interfaces.
  [[gnu::flatten]] int computeForcesAndAdvanceVelocities(const Model& m, const Materials& mat, const Operators& ops, State& s) {
    const cohesive::Law law = mat.law;
    NodeStep step;
    step.keep = 1.0 - 0.5 * dampA_ * dt_;
    step.scale = 1.0 + 0.5 * dampA_ * dt_;
    step.dt = dt_;
    step.b = bEff_;
    step.Vgrip = computeGripVelocity(mat.loading, s, 0.5 * dt_, dt_);
    vNext_.resize(s.vHalf.size());
    qNext_.resize(s.q.size());
    sliceSums_.assign(m.numSlices, SliceSums{});
    const double* q = s.q.data();
    const double* v = s.vHalf.data();
    double* lambda = s.lambdaMax.data();
    advanceInterfaceSchedule(m, law, ops, moveBound_, largestValue_, ifaceSchedule_);
    int failed = 0;
    long evaluated = 0;
#pragma omp parallel reduction(+ : failed, evaluated) firstprivate(law, q, v, lambda, step)
    {
      std::vector<double> wrench(6 * static_cast<std::size_t>(ops.maxNodesPerSlice));
      std::vector<DoublePair> KIq(3 * static_cast<std::size_t>(ops.maxNodesPerSlice));  // the slice's K_I q_n
      SliceOutputs out(ops, s, m.numSlices, sliceReach_, vNext_.data(), qNext_.data());
      for (int k = out.first; k < out.last; ++k) {
        const SliceCorrections pass =
            addInterfaceCorrectionsOfSliceScheduled(m, law, ops, k, q, lambda, ifaceSchedule_, wrench.data(), evaluated);
        failed += pass.failed;
        const SliceOutputs::Slot to = out.slotOf(k);
        // no wrench written: every node reads the same six zeros
        sliceSums_[k] = pass.wrench ? advanceNodesOfSlice(ops, step, k, q, v, wrench.data(), 6, KIq.data(), to.v, to.q)
                                    : advanceNodesOfSlice(ops, step, k, q, v, kNoWrench, 0, KIq.data(), to.v, to.q);
        out.replaceBefore(k);
      }
#pragma omp barrier
      out.replaceWaiting();
    }
    ifaceSchedule_.evaluated = evaluated;
    return failed;
  }

  // A slice's share of the damping work's two sums, and of the position update's maxima (pairs).
  struct SliceSums {
    DoublePair workM = {0, 0}, workK = {0, 0};  // the even DOFs' sums, the odd DOFs'
    DoublePair largestStep = {0, 0}, largestValue = {0, 0};
  };

  // The largest |slice of a block's column - slice of its row| of a node-block matrix (geometry.hpp numbers
  // nodes slice by slice: rods join neighbouring slices, or a few apart in a reduced far field; interfaces join
  // nodes of one slice).
  static int sliceReach(const Model& m, const NodeBlockMatrix& K) {
    int reach = 0;
    for (int R = 0; R < K.blockRows; ++R)
      for (int b = K.start[R]; b < K.start[R + 1]; ++b)
        reach = std::max(reach, std::abs(m.nodeSlice[K.column[b]] - m.nodeSlice[R]));
    return reach;
  }

  // Which of advanceNodesOfSlice's clones the loader picked (the tests its resolver makes), and whether K_I q
  // takes the AVX-512 rows.
  std::string nodeRowsTarget() const {
#if ENAMEL_HAS_CPU_CLONES
    if (cpuHasAvx512())
      return KIocts_.empty() ? "for x86-64-v4 (AVX-512)"
                             : "for x86-64-v4 (AVX-512; K_I rows on 8 doubles side by side)";
    if (__builtin_cpu_supports("x86-64-v3")) return "for x86-64-v3 (AVX2, FMA)";
#endif
    return "for x86-64 (this CPU has no AVX2 and FMA)";
  }

  // Where each slice's v_{n+1/2} and q_{n+1} go, for one thread's run of slices first .. last - 1 (the static
  // schedule's share of the thread), and when they replace v_{n-1/2} and q_n in the state. A slice's rows read
  // the slices up to sliceReach_ either side, so slice k's old values are read for the last time by slice
  // k + reach: slice k goes to a ring of reach + 1 buffers of the thread and replaces the old values once slice
  // k + reach is done (replaceBefore). The first and the last `reach` slices of the run are read by the
  // neighbouring threads' runs: they go to vNext_ and qNext_ and replace the old values after the pass
  // (replaceWaiting, after a barrier). Nothing else changes: each slice computes what it did with separate
  // old and new vectors, bit for bit.
  struct SliceOutputs {
    struct Slot {
      double *v, *q;  // the slice's first node's six entries; the others follow
    };
    const Operators& ops;
    State& s;
    int first = 0, last = 0, reach = 0;
    double *vWaiting, *qWaiting;  // state-sized: where the waiting slices go (vNext_, qNext_)
    std::vector<double> ring;     // reach + 1 slots of 12 maxNodesPerSlice doubles: v, then q
    SliceOutputs(const Operators& ops, State& s, int slices, int reach, double* vWaiting, double* qWaiting)
        : ops(ops), s(s), reach(reach), vWaiting(vWaiting), qWaiting(qWaiting) {
#if defined(_OPENMP)
      const int threads = omp_get_num_threads(), t = omp_get_thread_num();
#else
      const int threads = 1, t = 0;
#endif
      first = static_cast<int>(static_cast<long>(slices) * t / threads);
      last = static_cast<int>(static_cast<long>(slices) * (t + 1) / threads);
      ring.resize(12 * static_cast<std::size_t>(ops.maxNodesPerSlice) * (reach + 1));
    }
    bool waits(int k) const { return k < first + reach || k >= last - reach; }
    Slot slotOf(int k) {
      const int node = ops.sliceNodeStart[k];
      if (waits(k)) return {vWaiting + 6 * node, qWaiting + 6 * node};
      double* slot = ring.data() + 12 * static_cast<std::size_t>(ops.maxNodesPerSlice) * (k % (reach + 1));
      return {slot, slot + 6 * static_cast<std::size_t>(ops.maxNodesPerSlice)};
    }
    void replace(int k, const Slot& from) {
      const int node = ops.sliceNodeStart[k], count = 6 * (ops.sliceNodeStart[k + 1] - node);
      std::copy(from.v, from.v + count, s.vHalf.data() + 6 * node);
      std::copy(from.q, from.q + count, s.q.data() + 6 * node);
    }
    // once slice k is done: slice k - reach, unless it waits
    void replaceBefore(int k) {
      const int done = k - reach;
      if (done >= first && !waits(done)) replace(done, slotOf(done));
    }
    void replaceWaiting() {
      for (int k = first; k < last; ++k)
        if (waits(k)) replace(k, slotOf(k));
    }
  };

  // K_I q_n for every node of slice k into KIq (three pairs per node, from the slice's first), then advanceNode for
  // every node, W the wrench of its interfaces (node n's at W + stride (n - first node of the slice); stride 0: one
  // wrench for all), v_{n+1/2} and q_{n+1} to vOut and qOut (the slice's nodes in order, from its first).
  // K_I q_n has a loop of its own: a node's row is one chain of ~21 dependent multiply-adds, and the CPU overlaps
  // the chains of several nodes only when nothing else stands between them in the instruction stream (with
  // advanceNode's ~250 instructions between them, the nodes pass took 1.17x as long on the paper preset).
  // Where the CPU has AVX-512, K_I q by multiplyInterfaceRowsAvx512 (node_blocks.hpp: the same bits). Compiled
  // for three CPUs (target_clones), the loader picks one: x86-64-v4 (AVX-512), x86-64-v3 (AVX2, FMA: a * b + c
  // in one rounding where the code has one multiply and one add) where the CPU has them, else the default x86-64.
  ENAMEL_CPU_CLONES [[gnu::flatten]] SliceSums advanceNodesOfSlice(
      const Operators& ops, const NodeStep& c, int k, const double* q, const double* v, const double* W, int stride,
      DoublePair* KIq, double* vOut, double* qOut) {
    SliceSums sums;
    const int firstNode = ops.sliceNodeStart[k];
    const int lastNode = ops.sliceNodeStart[k + 1];
    if (!KIocts_.empty())
      multiplyInterfaceRowsAvx512(KI_, KIocts_, firstNode, lastNode, q, KIq);
    else
      for (int node = firstNode; node < lastNode; ++node)
        multiplyBlockRowGroups<kInterfaceGroups>(KI_, node, q, KIq + 3 * (node - firstNode));
    for (int node = firstNode; node < lastNode; ++node)
      advanceNode(ops, c, node, q, v, W + stride * (node - firstNode), KIq + 3 * (node - firstNode),
                  vOut + 6 * (node - firstNode), qOut + 6 * (node - firstNode), sums);
    return sums;
  }

  // One node's v_{n+1/2} into vTo from its block rows of K times q and v (= v_{n-1/2}), K_I q (KIq), and
  // the wrench of its interfaces beyond their elastic force W (f_iface = K_I q - W, so r = K q + K_I q - W + b' K v),
  // and its q_{n+1} = q_n + dt v_{n+1/2} into qTo
  // (the grips' q is prescribed afterwards); the sums v.Mv and v.Kv (even and odd DOFs side by side), max |dt v|
  // and max |q_{n+1}|. r and the free DOFs' v two at a time (the same operations per DOF); then the grips.
  [[gnu::always_inline]] inline void advanceNode(const Operators& ops, const NodeStep& c, int node, const double* q,
                                                 const double* v, const double* W, const DoublePair* KIq,
                                                 double* vTo, double* qTo, SliceSums& sums) {
    using Pair = DoublePair;
    const NodeBlockMatrix& K = Kblocks_;
    Pair Kq[3], Kv[3];
    if (!K.split.empty()) {
      multiplyBlockRowSplitPairs(K, node, q, v, Kq, Kv);
    } else {
      Vec6 a, b;
      multiplyBlockRow(K, node, q, v, a, b);
      for (int j = 0; j < 3; ++j) Kq[j] = Pair{a[2 * j], a[2 * j + 1]}, Kv[j] = Pair{b[2 * j], b[2 * j + 1]};
    }
    auto pairs = [node](const double* x) { return static_cast<const Pair*>(__builtin_assume_aligned(x + 6 * node, 16)); };
    const NodeMass& nodeMass = nodeMasses_[massOf_[node]];
    const Pair *vNode = pairs(v), *invM = nodeMass.invMass, *mass = nodeMass.mass;
    const Pair* Wp = static_cast<const Pair*>(__builtin_assume_aligned(W, 16));
    Pair r[3], vn[3];
    for (int j = 0; j < 3; ++j) {
      r[j] = ((Kq[j] + KIq[j]) - Wp[j]) + Pair{c.b, c.b} * Kv[j];
      vn[j] = (Pair{c.keep, c.keep} * vNode[j] - Pair{c.dt, c.dt} * (invM[j] * r[j])) / Pair{c.scale, c.scale};
    }
    if (nodeHasGrip_[node])
      for (int j = 0; j < 6; ++j) {
        const int grip = gripOfDof_[6 * node + j];
        if (grip < 0) continue;
        vn[j / 2][j % 2] = ops.prescribedShape[grip] * c.Vgrip;
        gripResidual_[grip] = r[j / 2][j % 2];
      }
    auto absMax = [](Pair m, Pair a) {
      const Pair mag = magnitude(a);
      return mag > m ? mag : m;
    };
    Pair* vOut = static_cast<Pair*>(__builtin_assume_aligned(vTo, 16));
    Pair* qOut = static_cast<Pair*>(__builtin_assume_aligned(qTo, 16));
    const Pair* qNode = pairs(q);
    for (int j = 0; j < 3; ++j) {
      vOut[j] = vn[j];
      sums.workM += vn[j] * (mass[j] * vn[j]), sums.workK += vn[j] * Kv[j];
      const Pair stepj = Pair{c.dt, c.dt} * vn[j], y = qNode[j] + stepj;
      qOut[j] = y;
      sums.largestStep = absMax(sums.largestStep, stepj), sums.largestValue = absMax(sums.largestValue, y);
    }
  }

  // The six masses and inverse masses of a node (equal to mass_ and invMass_ there), as pairs: they take a few
  // distinct values (a node's rod elements and their spans decide them), kept once each and found by massOf_.
  struct NodeMass {
    DoublePair mass[3], invMass[3];
  };
  void classifyNodeMasses(int nodes) {
    std::map<std::array<double, 12>, int> index;
    massOf_.resize(nodes);
    nodeMasses_.clear();
    for (int node = 0; node < nodes; ++node) {
      std::array<double, 12> key;
      for (int i = 0; i < 6; ++i) key[i] = mass_[6 * node + i], key[6 + i] = invMass_[6 * node + i];
      const auto [it, added] = index.emplace(key, static_cast<int>(nodeMasses_.size()));
      if (added) {
        NodeMass nm;
        for (int j = 0; j < 3; ++j)
          nm.mass[j] = DoublePair{key[2 * j], key[2 * j + 1]}, nm.invMass[j] = DoublePair{key[6 + 2 * j], key[7 + 2 * j]};
        nodeMasses_.push_back(nm);
      }
      massOf_[node] = it->second;
    }
  }

  // R_p = K q + f_iface + b' K v_{n-1/2} + m_p (a_p + a v_p) at t_n, with
  // a_p = (v_{n+1/2} - v_{n-1/2}) / dt and v_p = (v_{n+1/2} + v_{n-1/2}) / 2 (kept in vGrip_)
  void computeReactions(const Operators& ops, State& s) {
    vGrip_.resize(vGripBefore_.size());
    for (std::size_t i = 0; i < ops.prescribedDofs.size(); ++i) {
      const int dof = ops.prescribedDofs[i];
      const double acc = (s.vHalf[dof] - vGripBefore_[i]) / dt_, vel = 0.5 * (s.vHalf[dof] + vGripBefore_[i]);
      s.reaction[i] = gripResidual_[i] + mass_[dof] * (acc + dampA_ * vel);
      vGrip_[i] = vel;
    }
  }

  // W_damp += dt (a v_{n+1/2} . M v_{n+1/2} + b' v_{n+1/2} . K v_{n-1/2}), the sums in slice order
  void addDampingWork(State& s) const {
    double sumM = 0, sumK = 0;
    for (const SliceSums& k : sliceSums_) { sumM += k.workM[0] + k.workM[1]; sumK += k.workK[0] + k.workK[1]; }
    s.dampingWork += dt_ * (dampA_ * sumM + bEff_ * sumK);
  }

  // What the node pass's q_{n+1} = q_n + dt v_{n+1/2} moved (it has replaced q_n and v_{n-1/2} already)
  PositionMove moveOfStep() const {
    PositionMove move;
    for (const SliceSums& k : sliceSums_) {  // maxima: exact in any order
      move.largestStep = std::max({move.largestStep, k.largestStep[0], k.largestStep[1]});
      move.largestValue = std::max({move.largestValue, k.largestValue[0], k.largestValue[1]});
    }
    return move;
  }

  // max_i |q_{n+1,i} - q_{n,i}|: a free DOF moved by fl(q + dt v) - q, at most |dt v| plus half an ulp of the
  // result; a grip by shape (U_{n+1} - U_n) plus the round-off of both products. So the larger of the two moves,
  // plus 2^-52 of the largest |q| (an ulp), with a relative 1e-12 for the products.
  double boundOfMove(const PositionMove& move, double Ubefore, double Uafter) const {
    const double grips = largestShape_ * std::abs(Uafter - Ubefore);
    const double largest = std::max({move.largestValue, largestShape_ * std::abs(Uafter), largestShape_ * std::abs(Ubefore)});
    return std::max(move.largestStep, grips) * (1.0 + 1e-12) + std::ldexp(largest, -52);
  }

  double dt_ = 0, rotaryScale_ = 1, omegaMax_ = 0, bEff_ = 0, dampA_ = 0;
  double largestShape_ = 0;          // max |shape| of the prescribed DOFs
  double moveBound_ = INFINITY;      // lastStepMoveBound (infinite: q was set otherwise, the schedules start afresh)
  double largestValue_ = INFINITY;   // a bound on max |q_n|
  InterfaceSchedule ifaceSchedule_;  // which interfaces the law must see (kernels.hpp)
  VecX mass_, invMass_, fI_, vNext_, qNext_, vGripBefore_, vGrip_, gripResidual_;
  std::vector<int> gripOfDof_;                 // index into ops.prescribedDofs; -1 for a free DOF
  std::vector<std::uint8_t> nodeHasGrip_;      // per node: 1 when one of its DOFs is prescribed
  std::vector<SliceSums> sliceSums_;  // per slice
  NodeBlockMatrix Kblocks_;  // ops.K in node blocks, for the fused product
  NodeBlockMatrix KI_;       // the elastic interfaces' stiffness K_I in node blocks (kernels.hpp)
  std::vector<StoredOct> KIocts_;  // KI_'s blocks as octs where the CPU has AVX-512 (K_I q by
                                   // multiplyInterfaceRowsAvx512); empty otherwise
  std::vector<NodeMass> nodeMasses_;  // the distinct NodeMass values
  std::vector<int> massOf_;           // per node: its NodeMass in nodeMasses_
  int sliceReach_ = 1;                // how many slices either side a node's rows read (SliceOutputs)
};

}  // namespace

std::unique_ptr<Integrator> makeIntegrator(const CaseParams& p, const Model& m, const Materials& mat,
                                           const Operators& ops) {
  if (p.integrator == "paper") return std::make_unique<PaperIntegrator>(p, mat, ops);
  if (p.integrator == "lumped") return std::make_unique<LumpedIntegrator>(p, m, mat, ops);
  throw IntegratorError("integrator '" + p.integrator + "' is not available in this build (available: paper, lumped)");
}

}  // namespace enamel
