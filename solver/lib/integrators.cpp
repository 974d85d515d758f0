#include "integrators.hpp"

#include <cmath>
#include <sstream>

#include <Eigen/CholmodSupport>
#include <Eigen/UmfPackSupport>

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

// The paper's scheme (eq. 12-15): Newmark beta = 0 with consistent mass and Rayleigh damping,
//   q_{n+1} = q_n + dt v_n + dt^2/2 a_n
//   H a_{n+1} = f - f_iface(q_{n+1}) - K q_{n+1} - C (v_n + dt/2 a_n),   H = M + dt/2 C
//   v_{n+1} = v_n + dt/2 (a_n + a_{n+1})
// H is factorised once (CHOLMOD Cholesky, or UMFPACK LU) and re-factorised after rod deletions. Prescribed
// DOFs are eliminated: H_ff a_f = r_f - H_fp a_p.
class PaperIntegrator : public Integrator {
 public:
  explicit PaperIntegrator(Simulation& sim) : useUmfpack_(sim.params.linear_solver == "umfpack") {
    dt_ = sim.params.dt_factor * 2.0 * M_PI / sim.omegaMaxElement;
    const double limit = 2.0 / sim.omegaMaxElement;
    // Interfaces add stiffness (about k A_i per node against E A / L for the beams): keep 5% margin.
    if (dt_ > 0.95 * limit) {
      std::ostringstream msg;
      msg << "time step dt = " << dt_ << " (dt_factor " << sim.params.dt_factor
          << " x smallest element period) is above the stable limit 0.95 x 2/omega_max = " << 0.95 * limit
          << " (omega_max = " << sim.omegaMaxElement << "): use dt_factor <= "
          << 0.95 * limit * sim.omegaMaxElement / (2 * M_PI);
      throw IntegratorError(msg.str());
    }
    factorise(sim, true);
  }

  std::string name() const override { return "paper"; }
  double timeStep() const override { return dt_; }

  void advance(Simulation& sim) override {
    State& s = sim.state;
    const double dt = dt_, a = sim.dampA, b = sim.dampB;
    w_ = s.v + 0.5 * dt * s.a;
    s.q += dt * s.v + 0.5 * dt * dt * s.a;
    s.time += dt;
    ++s.step;
    sim.applyBoundaryConditions(s.time);
    fI_.resize(s.q.size());
    sim.computeForcesForInterfaces(s.q, fI_, true);
    Kq_ = sim.K * s.q;
    Kw_ = sim.K * w_;
    Mw_ = sim.M * w_;
    r_ = -fI_ - Kq_ - b * Kw_ - a * Mw_;
    const std::vector<int>& freeDofs = sim.freeDofs;
    const std::vector<int>& pres = sim.prescribedDofs;
    VecX ap(pres.size());
    for (std::size_t i = 0; i < pres.size(); ++i) ap[i] = s.a[pres[i]];
    rf_.resize(freeDofs.size());
    for (std::size_t i = 0; i < freeDofs.size(); ++i) rf_[i] = r_[freeDofs[i]];
    rf_ -= Hfp_ * ap;
    af_ = useUmfpack_ ? VecX(lu_.solve(rf_)) : VecX(chol_.solve(rf_));
    for (std::size_t i = 0; i < freeDofs.size(); ++i) {
      const int dof = freeDofs[i];
      s.a[dof] = af_[i];
      s.v[dof] = w_[dof] + 0.5 * dt * af_[i];
    }
    // Work of the damping force over the step, at the mid-step velocity w.
    s.dampingWork += dt * w_.dot(a * Mw_ + b * Kw_);
    // Reactions: the force the grips apply, R_p = (M a + C v + K q + f_iface)_p.
    sim.reaction = Mp_ * s.a + a * (Mp_ * s.v) + b * (Kp_ * s.v);
    double power = 0;
    for (std::size_t i = 0; i < pres.size(); ++i) {
      sim.reaction[i] += Kq_[pres[i]] + fI_[pres[i]];
      power += sim.reaction[i] * s.v[pres[i]];
    }
    s.externalWork += 0.5 * dt * (s.lastExternalPower + power);
    s.lastExternalPower = power;
  }

  void onBeamsDeleted(Simulation& sim) override { factorise(sim, false); }

  double kineticEnergy(const Simulation& sim) const override {
    return 0.5 * sim.state.v.dot(sim.M * sim.state.v);
  }

 private:
  void factorise(Simulation& sim, bool first) {
    const SpMat H = (1.0 + 0.5 * dt_ * sim.dampA) * sim.M + (0.5 * dt_ * sim.dampB) * sim.K;
    std::vector<Eigen::Triplet<double>> tff, tfp;
    std::vector<int> presIndex(H.rows(), -1);
    for (std::size_t i = 0; i < sim.prescribedDofs.size(); ++i) presIndex[sim.prescribedDofs[i]] = static_cast<int>(i);
    for (int c = 0; c < H.outerSize(); ++c)
      for (SpMat::InnerIterator it(H, c); it; ++it) {
        const int fr = sim.dofToFree[it.row()];
        if (fr < 0) continue;
        const int fc = sim.dofToFree[c];
        if (fc >= 0) tff.emplace_back(fr, fc, it.value());
        else tfp.emplace_back(fr, presIndex[c], it.value());
      }
    const Eigen::Index nf = static_cast<Eigen::Index>(sim.freeDofs.size());
    SpMat Hff(nf, nf);
    Hff.setFromTriplets(tff.begin(), tff.end());
    Hfp_.resize(nf, static_cast<Eigen::Index>(sim.prescribedDofs.size()));
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
    if (!ok) throw IntegratorError("factorisation of H = M + dt/2 C failed (matrix not positive definite?)");
    Mp_ = selectRows(sim.M, sim.prescribedDofs);
    Kp_ = selectRows(sim.K, sim.prescribedDofs);
  }

  double dt_ = 0;
  bool useUmfpack_ = false;
  Eigen::CholmodSupernodalLLT<SpMat> chol_;
  Eigen::UmfPackLU<SpMat> lu_;
  SpMat Hfp_, Mp_, Kp_;
  VecX w_, fI_, Kq_, Kw_, Mw_, r_, rf_, af_;
};

}  // namespace

std::unique_ptr<Integrator> makeIntegrator(Simulation& sim) {
  const std::string& name = sim.params.integrator;
  if (name == "paper") return std::make_unique<PaperIntegrator>(sim);
  throw IntegratorError("integrator '" + name + "' is not available in this build (available: paper)");
}

}  // namespace enamel
