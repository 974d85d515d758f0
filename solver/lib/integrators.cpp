#include "integrators.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <unordered_map>

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

  void initialise(Simulation& sim) override {
    State& s = sim.state;
    sim.applyBoundaryConditions(s.time);
    fI_.resize(s.q.size());
    sim.computeForcesForInterfaces(s.q, fI_, false);
    r_ = -fI_ - sim.K * s.q - sim.dampB * (sim.K * s.v) - sim.dampA * (sim.M * s.v);
    VecX ap(sim.prescribedDofs.size());
    for (std::size_t i = 0; i < ap.size(); ++i) ap[i] = s.a[sim.prescribedDofs[i]];
    rf_.resize(sim.freeDofs.size());
    for (std::size_t i = 0; i < sim.freeDofs.size(); ++i) rf_[i] = r_[sim.freeDofs[i]];
    rf_ -= Hfp_ * ap;
    af_ = useUmfpack_ ? VecX(lu_.solve(rf_)) : VecX(chol_.solve(rf_));
    for (std::size_t i = 0; i < sim.freeDofs.size(); ++i) s.a[sim.freeDofs[i]] = af_[i];
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


// Rotary-inertia scale for the lumped element (DESIGN section 4): with physical rotary inertia the short
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
double estimateOmegaMax(Simulation& sim, const VecX& invMass) {
  const int n = static_cast<int>(invMass.size());
  VecX x = VecX::Zero(n), f(n), y(n);
  std::uint64_t seed = 12345;  // fixed start vector: the estimate is deterministic
  for (int dof : sim.freeDofs) {
    seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
    x[dof] = static_cast<double>(seed >> 11) / 9007199254740992.0 - 0.5;
  }
  // the case's delta0 (not the law's: unbreakable interfaces have an infinite one)
  const double amplitude = 1e-3 * sim.params.sigma0() / sim.params.k();
  double lambda = 0;
  for (int it = 0; it < 300; ++it) {
    x *= amplitude / x.cwiseAbs().maxCoeff();
    sim.computeForcesForInterfaces(x, f, false);
    y = invMass.cwiseProduct(sim.K * x + f);
    for (int dof : sim.prescribedDofs) y[dof] = 0;
    const double next = x.dot(y.cwiseQuotient(invMass)) / x.dot(x.cwiseQuotient(invMass));
    x = y;
    if (it > 20 && std::abs(next - lambda) < 1e-6 * next) { lambda = next; break; }
    lambda = next;
  }
  return std::sqrt(std::max(lambda, 0.0));
}

using SpMatRow = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// K in 6 x 6 node blocks (block compressed rows): one column index per block instead of one per entry, and
// the six rows of a node summed side by side. The beam stiffness is assembled from whole 12 x 12 element
// matrices, so every stored block is full; and since every element of a ply has the same matrix, the blocks
// take only a handful of distinct values (10 in the bench's cases), kept once each: the product reads two
// integers per block instead of 36 doubles.
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;  // column-major, as the blocks are stored

struct NodeBlockMatrix {
  int blockRows = 0;
  std::vector<int> start;      // block row R holds blocks start[R] .. start[R + 1] - 1
  std::vector<int> column;     // block column of each block
  std::vector<int> valueOf;    // each block's entry in `values`
  std::vector<double> values;  // distinct blocks, column-major: block v, entry (i, j) at values[36 v + 6 j + i]
};

NodeBlockMatrix toNodeBlocks(const SpMatRow& K) {
  if (K.rows() % 6 != 0) throw IntegratorError("stiffness matrix: size not a multiple of 6");
  NodeBlockMatrix B;
  B.blockRows = static_cast<int>(K.rows() / 6);
  B.start.assign(1, 0);
  std::unordered_map<std::string, int> distinct;  // a block's 36 values, bit for bit -> its index
  std::array<double, 36> block;
  for (int R = 0; R < B.blockRows; ++R) {
    const int first = static_cast<int>(K.outerIndexPtr()[6 * R]), count = K.outerIndexPtr()[6 * R + 1] - first;
    if (count % 6 != 0) throw IntegratorError("stiffness matrix: a row is not made of whole 6 x 6 blocks");
    for (int k = 0; k < count; k += 6) {
      const int c = K.innerIndexPtr()[first + k];
      if (c % 6 != 0) throw IntegratorError("stiffness matrix: a block does not start on a node");
      for (int j = 0; j < 6; ++j)
        for (int i = 0; i < 6; ++i) {
          const int row = 6 * R + i, at = K.outerIndexPtr()[row] + k + j;
          if (K.outerIndexPtr()[row + 1] - K.outerIndexPtr()[row] != count || K.innerIndexPtr()[at] != c + j)
            throw IntegratorError("stiffness matrix: the rows of a node do not share one block pattern");
          block[6 * j + i] = K.valuePtr()[at];
        }
      const std::string key(reinterpret_cast<const char*>(block.data()), sizeof block);
      const auto [it, added] = distinct.emplace(key, static_cast<int>(distinct.size()));
      if (added) B.values.insert(B.values.end(), block.begin(), block.end());
      B.column.push_back(c / 6);
      B.valueOf.push_back(it->second);
    }
    B.start.push_back(static_cast<int>(B.column.size()));
  }
  return B;
}

// y1 = K x1 and y2 = K x2 in one pass over K (the matrix is read once for both products). Rows are
// independent and each row sums its entries in ascending column order, as a compressed-row product would,
// so the result is the same bit for bit and does not depend on the thread count.
void multiplyTwo(const NodeBlockMatrix& K, const VecX& x1, const VecX& x2, VecX& y1, VecX& y2) {
  y1.resize(6 * K.blockRows);
  y2.resize(6 * K.blockRows);
#pragma omp parallel for schedule(static)
  for (int R = 0; R < K.blockRows; ++R) {
    // column by column, each row's sum in ascending column order (never a partial product added at once)
    Vec6 s1 = Vec6::Zero(), s2 = Vec6::Zero();
    for (int b = K.start[R]; b < K.start[R + 1]; ++b) {
      const Eigen::Map<const Mat6> block(K.values.data() + 36 * static_cast<std::size_t>(K.valueOf[b]));
      const double* a1 = x1.data() + 6 * K.column[b];
      const double* a2 = x2.data() + 6 * K.column[b];
      for (int j = 0; j < 6; ++j) {
        s1 += block.col(j) * a1[j];
        s2 += block.col(j) * a2[j];
      }
    }
    y1.segment<6>(6 * R) = s1;
    y2.segment<6>(6 * R) = s2;
  }
}

// Fast scheme `lumped` (ours, DESIGN section 4): explicit central differences with a diagonal mass.
//   M: lumped rod mass, translations rho A L / 2 per element end; rotations an isotropic rotary inertia
//      alpha rho Ip L / 2 per element end, alpha the smallest scale at which rotations stop governing.
//   C = a M + b' K with b' = min(b, c/omega_max), c = damping_cap (default 1: the stiffness part's damping
//      ratio at omega_max is at most 1/2; an explicit stiffness damping above that would need a far smaller
//      step, and a lower cap allows a larger one).
//   v_{n+1/2} = [(1 - a dt/2) v_{n-1/2} + dt M^-1 (-K q_n - f_iface(q_n) - b' K v_{n-1/2})] / (1 + a dt/2)
//   q_{n+1}   = q_n + dt v_{n+1/2}
//   dt = dt_factor x 2 pi / omega_max (the smallest period of this system), refused above the limit
//   2 / omega_max (sqrt(1 + xi^2) - xi), xi = b' omega_max / 2.
class LumpedIntegrator : public Integrator {
 public:
  explicit LumpedIntegrator(Simulation& sim) {
    const Model& m = sim.model;
    const double L = m.beamLength;
    rotaryScale_ = rotaryScaleForTranslationalLimit(sim.section, L);
    Kblocks_ = toNodeBlocks(SpMatRow(sim.K));
    const double mt = 0.5 * sim.section.rho * sim.section.A * L;
    const double jr = rotaryScale_ * 0.5 * sim.section.rho * sim.section.Ip * L;
    mass_ = VecX::Zero(m.numDofs());
    auto addElementMass = [&](int a, int b) {
      for (int node : {a, b})
        for (int k = 0; k < 3; ++k) { mass_[6 * node + k] += mt; mass_[6 * node + 3 + k] += jr; }
    };
    for (int e = 0; e < m.numBeams(); ++e) addElementMass(m.beamNodes[e][0], m.beamNodes[e][1]);
    for (const auto& ab : sim.cutBeamNodes) addElementMass(ab[0], ab[1]);  // cut by the pre-crack: mass stays
    for (int i = 0; i < mass_.size(); ++i)
      if (mass_[i] <= 0) throw IntegratorError("node without rod mass: the lumped integrator needs every node on a rod");
    invMass_ = mass_.cwiseInverse();
    sim.addedRotaryInertia = rotaryScale_ - 1.0;
    omegaMax_ = estimateOmegaMax(sim, invMass_);
    bEff_ = std::min(sim.dampB, sim.params.damping_cap / omegaMax_);
    dt_ = sim.params.dt_factor * 2.0 * M_PI / omegaMax_;
    const double xi = 0.5 * bEff_ * omegaMax_ + 0.5 * sim.dampA / omegaMax_;
    const double limit = 2.0 / omegaMax_ * (std::sqrt(1.0 + xi * xi) - xi);
    if (dt_ > 0.95 * limit) {
      std::ostringstream msg;
      msg << "time step dt = " << dt_ << " (dt_factor " << sim.params.dt_factor
          << " x smallest period 2 pi/omega_max of the lumped system) is above the stable limit 0.95 x "
          << limit << " (omega_max = " << omegaMax_ << ", damping ratio there " << xi
          << "): use dt_factor <= " << 0.95 * limit * omegaMax_ / (2 * M_PI);
      throw IntegratorError(msg.str());
    }
  }

  std::string name() const override { return "lumped"; }
  double timeStep() const override { return dt_; }
  bool usesConsistentMass() const override { return false; }
  std::string describe() const override {
    std::ostringstream o;
    o << "lumped mass, rotary inertia x " << rotaryScale_ << ", omega_max " << omegaMax_
      << ", stiffness damping b' " << bEff_ << ", " << Kblocks_.values.size() / 36
      << " distinct 6x6 stiffness blocks";
    return o.str();
  }

  void advance(Simulation& sim) override {
    State& s = sim.state;  // s.v holds the half-step velocity v_{n-1/2} (checkpointable as it is); s.a is unused
    const double dt = dt_, a = sim.dampA;
    const std::vector<int>& pres = sim.prescribedDofs;
    // forces at q_n (interfaces update their history here), stiffness damping at v_{n-1/2}
    fI_.resize(s.q.size());
    sim.computeForcesForInterfaces(s.q, fI_, true);
    multiplyTwo(Kblocks_, s.q, s.v, Kq_, Kv_);
    vPresOld_.resize(pres.size());
    for (std::size_t i = 0; i < pres.size(); ++i) vPresOld_[i] = s.v[pres[i]];
    s.v = ((1.0 - 0.5 * a * dt) * s.v - dt * invMass_.cwiseProduct(Kq_ + fI_ + bEff_ * Kv_)) / (1.0 + 0.5 * a * dt);
    // prescribed DOFs follow the loading, at the half step
    const double Vh = sim.loading.velocity(s.time + 0.5 * dt);
    for (std::size_t i = 0; i < pres.size(); ++i) s.v[pres[i]] = sim.prescribedShape[i] * Vh;
    // reactions at t_n: R_p = (K q + f_iface + M a + C v)_p, with a and v by central differences
    double power = 0;
    for (std::size_t i = 0; i < pres.size(); ++i) {
      const int dof = pres[i];
      const double acc = (s.v[dof] - vPresOld_[i]) / dt, vel = 0.5 * (s.v[dof] + vPresOld_[i]);
      sim.reaction[i] = Kq_[dof] + fI_[dof] + bEff_ * Kv_[dof] + mass_[dof] * (acc + a * vel);
      power += sim.reaction[i] * vel;
    }
    if (s.step > 0) s.externalWork += 0.5 * dt * (s.lastExternalPower + power);
    s.lastExternalPower = power;
    // damping work over the step: the step's displacement dt v_{n+1/2} against the damping force, its
    // stiffness part as applied (at the lagged velocity)
    s.dampingWork += dt * (a * s.v.dot(mass_.cwiseProduct(s.v)) + bEff_ * s.v.dot(Kv_));
    s.q += dt * s.v;
    s.time += dt;
    ++s.step;
    sim.applyBoundaryConditions(s.time);  // q of the prescribed DOFs at t_{n+1} (it also sets their v to t_{n+1}):
    for (std::size_t i = 0; i < pres.size(); ++i) s.v[pres[i]] = sim.prescribedShape[i] * Vh;  // keep v_{n+1/2}
  }

  void initialise(Simulation& sim) override {
    State& s = sim.state;
    sim.applyBoundaryConditions(s.time);
    fI_.resize(s.q.size());
    sim.computeForcesForInterfaces(s.q, fI_, false);
    const VecX acc = -invMass_.cwiseProduct(fI_ + sim.K * s.q + bEff_ * (sim.K * s.v)) - sim.dampA * s.v;
    for (int dof : sim.freeDofs) s.v[dof] -= 0.5 * dt_ * acc[dof];
    const double Vh = sim.loading.velocity(s.time - 0.5 * dt_);
    for (std::size_t i = 0; i < sim.prescribedDofs.size(); ++i) s.v[sim.prescribedDofs[i]] = sim.prescribedShape[i] * Vh;
  }

  void onBeamsDeleted(Simulation& sim) override {  // lumped mass stays; K is already updated in sim
    Kblocks_ = toNodeBlocks(SpMatRow(sim.K));
  }

  double kineticEnergy(const Simulation& sim) const override {
    return 0.5 * sim.state.v.dot(mass_.cwiseProduct(sim.state.v));
  }

 private:
  double dt_ = 0, rotaryScale_ = 1, omegaMax_ = 0, bEff_ = 0;
  VecX mass_, invMass_, vPresOld_, fI_, Kq_, Kv_;
  NodeBlockMatrix Kblocks_;  // sim.K in node blocks, for the fused product
};

}  // namespace

std::unique_ptr<Integrator> makeIntegrator(Simulation& sim) {
  const std::string& name = sim.params.integrator;
  if (name == "paper") return std::make_unique<PaperIntegrator>(sim);
  if (name == "lumped") return std::make_unique<LumpedIntegrator>(sim);
  throw IntegratorError("integrator '" + name + "' is not available in this build (available: paper, lumped)");
}

}  // namespace enamel
