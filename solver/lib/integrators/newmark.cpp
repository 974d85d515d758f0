// Scheme `paper` (Pro & Barthelat 2020, eq. 12-18): Newmark beta = 0, consistent mass, Rayleigh damping; the
// reference the fast schemes are judged against (docs/solver.md).
#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/CholmodSupport>
#include <Eigen/UmfPackSupport>

#include "integrators/schemes.hpp"
#include "integrators/step_parts.hpp"
#include "kernels/kernels.hpp"

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
      : useUmfpack_(p.linear_solver == LinearSolver::umfpack), dampA_(mat.dampA), dampB_(mat.dampB) {
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

  std::string name() const override { return nameOf(IntegratorScheme::paper); }
  double timeStep() const override { return dt_; }

  // The step as the class comment lists it; each lap books the calls before it to their phase (step_timers.hpp).
  void advance(const Model& m, const Materials& mat, const Operators& ops, State& s) override {
    PhaseLaps laps(timers_);
    predictVelocities(s);
    advancePositions(s);
    laps.lap(StepPhase::PaperPositions);
    advanceClock(mat.loading, s, dt_);
    applyBoundaryConditions(ops, mat.loading, dt_, s);
    laps.lap(StepPhase::PaperBoundaryConditions);
    s.failedInterfaces = computeForcesForInterfaces(m, mat.law, ops, s.q, s.lambdaMax, true, fI_);
    laps.lap(StepPhase::PaperInterfaces);
    computeForcesForBeams(ops, s);
    laps.lap(StepPhase::PaperRodForces);
    solveAccelerations(ops, s);
    laps.lap(StepPhase::PaperAccelerations);
    advanceVelocities(ops, s);
    addDampingWork(s);
    laps.lap(StepPhase::PaperVelocities);
    computeReactions(ops, s);
    gatherGrips(ops, s.v, vGrip_);
    addWorkOfGrips(s, computeGripPower(s.reaction, vGrip_), dt_);
    laps.lap(StepPhase::PaperReactions);
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
  double addToFreeVelocities(const Operators& ops, State& s, double c) const override {
    VecX dv = VecX::Zero(s.v.size());
    for (int dof : ops.freeDofs) dv[dof] = c * s.q[dof];
    const VecX Mdv = ops.M * dv;
    const double added = Mdv.dot(s.v) + 0.5 * Mdv.dot(dv);
    s.v += dv;
    return added;
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

}  // namespace

std::unique_ptr<Integrator> makePaperIntegrator(const CaseParams& p, const Model&, const Materials& mat,
                                                const Operators& ops) {
  return std::make_unique<PaperIntegrator>(p, mat, ops);
}

// Peak resident memory (VmHWM, /meta/peak_memory_mb) measured on theta30, 20 steps, 1 thread: 40 x 20 d: 4640
// nodes 65 MB; 40 x 40 d: 9284 nodes 120 MB -> 6.4 kB per node + ~52 B per node per node of a slice (the
// Cholesky factor's fill grows with the bandwidth); rounded up by ~10%.
// Seconds per step (consistent mass, CHOLMOD solve per step), per DOF: a + b x nodes of a slice (the factor's
// bandwidth); one core, CPU (user) seconds, measured 9.7e-8 s at 16 x 8 d (13.9 nodes a slice) and 1.22e-7 at
// 40 x 20 d (34.6), 3000 and 600 steps less a 1-step run; 1.92e-7 at 80 x 40 d (69.3) by `make bench`'s cost
// growth. The constants give 1.11x, 1.22x and 1.14x of these; at the paper preset's 346 nodes a slice, an
// extrapolation.
SchemeCosts paperCosts(const CaseParams&, const SchemeSizes& n) {
  constexpr double kBytesPerNode = 6500, kFillBytesPerNodeSliceNode = 60;
  constexpr double kSecondsPerDof = 8e-8, kSecondsPerDofSliceNode = 2e-9;
  return SchemeCosts{n.nodes * (kBytesPerNode + kFillBytesPerNodeSliceNode * n.nodesPerSlice),
                     n.dof * (kSecondsPerDof + kSecondsPerDofSliceNode * n.nodesPerSlice)};
}

}  // namespace enamel
