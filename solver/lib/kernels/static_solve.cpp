#include "kernels/static_solve.hpp"

#include <dlfcn.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <Eigen/CholmodSupport>

#include "kernels/kernels.hpp"

namespace enamel {

void setBlasThreadCount(int n) {
  using SetThreads = void (*)(int);
  if (auto set = reinterpret_cast<SetThreads>(dlsym(RTLD_DEFAULT, "openblas_set_num_threads"))) set(n);
}

int blasThreadCount() {
  using GetThreads = int (*)();
  auto get = reinterpret_cast<GetThreads>(dlsym(RTLD_DEFAULT, "openblas_get_num_threads"));
  return get ? get() : 0;
}

namespace {
// The BLAS at one thread while this lives, its count before restored after.
struct OneBlasThread {
  const int before = blasThreadCount();
  OneBlasThread() { if (before > 1) setBlasThreadCount(1); }
  ~OneBlasThread() { if (before > 1) setBlasThreadCount(before); }
  OneBlasThread(const OneBlasThread&) = delete;
  OneBlasThread& operator=(const OneBlasThread&) = delete;
};
}  // namespace

void addElementTriplets(std::vector<Eigen::Triplet<double>>& trip, const beam::Mat12& Ke, int a, int b) {
  const int dof[2] = {6 * a, 6 * b};
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j)
      trip.emplace_back(dof[i / 6] + i % 6, dof[j / 6] + j % 6, Ke(i, j));
}

VecX solveStaticPrescribed(const SpMat& K, const std::vector<int>& dofs, const std::vector<double>& values,
                           bool* mechanism) {
  if (mechanism) *mechanism = false;
  const int n = static_cast<int>(K.rows());
  std::vector<double> uPres(n, 0.0);
  std::vector<int> freeIdx(n, 0);
  for (std::size_t i = 0; i < dofs.size(); ++i) { freeIdx[dofs[i]] = -1; uPres[dofs[i]] = values[i]; }
  int nf = 0;
  for (int i = 0; i < n; ++i)
    if (freeIdx[i] == 0) freeIdx[i] = nf++;
  std::vector<Eigen::Triplet<double>> tff;
  VecX rhs = VecX::Zero(nf);
  for (int c = 0; c < K.outerSize(); ++c)
    for (SpMat::InnerIterator it(K, c); it; ++it) {
      const int r = static_cast<int>(it.row());
      if (freeIdx[r] < 0) continue;
      if (freeIdx[c] >= 0) tff.emplace_back(freeIdx[r], freeIdx[c], it.value());
      else rhs[freeIdx[r]] -= it.value() * uPres[c];
    }
  SpMat Kff(nf, nf);
  Kff.setFromTriplets(tff.begin(), tff.end());
  const OneBlasThread oneThread;
  Eigen::CholmodSupernodalLLT<SpMat> chol;
  chol.cholmod().print = 0;  // a factorisation that fails is handled below, not printed
  chol.compute(Kff);
  VecX uf;
  if (chol.info() == Eigen::Success) {
    uf = chol.solve(rhs);
  } else {
    // K_ff only semi-definite: a part of the model is a mechanism (e.g. a rod end that the pre-crack's cut
    // leaves on a single interface, free to turn about it; the explicit schemes carry it on its mass). The
    // prescribed displacements do no work on a mechanism (the right-hand side is orthogonal to K's null
    // space), so any solution serves: factor K_ff + s I with s = 1e-10 of its largest diagonal entry (the
    // mechanism then stays where it is) and refine against K_ff itself, which removes the shift's error from
    // every mode with stiffness (each refinement multiplies it by s / (lambda + s)).
    const double shift = 1e-10 * Kff.diagonal().cwiseAbs().maxCoeff();
    chol.setShift(shift);
    chol.factorize(Kff);
    if (chol.info() != Eigen::Success) throw std::runtime_error("static solve: stiffness factorisation failed");
    uf = chol.solve(rhs);
    for (int it = 0; it < 4; ++it) uf += chol.solve(rhs - Kff * uf);
    if (mechanism) *mechanism = true;
  }
  VecX u(n);
  for (int i = 0; i < n; ++i) u[i] = freeIdx[i] >= 0 ? uf[freeIdx[i]] : uPres[i];
  return u;
}

SpMat assembleElasticStiffness(const Model& m, const std::vector<beam::Mat12>& beamKPerClass,
                               const std::vector<std::uint8_t>* beamBroken, const cohesive::Law& law) {
  std::vector<Eigen::Triplet<double>> trip;
  for (int e = 0; e < m.numBeams(); ++e)
    if (!beamBroken || !(*beamBroken)[e])
      addElementTriplets(trip, beamKPerClass[m.beamClass(e)], m.beamNodes[e][0], m.beamNodes[e][1]);
  for (int i = 0; i < m.numInterfaces(); ++i)
    addElementTriplets(trip, cohesive::elasticStiffness(law, m.ifaceGeom[i]), m.ifaceNodes[i][0], m.ifaceNodes[i][1]);
  SpMat K(m.numDofs(), m.numDofs());
  K.setFromTriplets(trip.begin(), trip.end());
  return K;
}

double computeFirstDamageDisplacement(const Model& m, const Materials& mat, const VecX& q1,
                                      const std::vector<std::uint8_t>& beamBroken, bool interfacesBreakable,
                                      bool& limitedByRod) {
  double uc = INFINITY;
  limitedByRod = false;
  if (interfacesBreakable && m.numInterfaces() > 0) {
    // the largest effective separation lambda_i(q1) (no interface is assembled or changed)
    double worst = 0;
    for (int i = 0; i < m.numInterfaces(); ++i)
      worst = std::max(worst, cohesive::effectiveSeparation(mat.law, computeLocalOpening(m, q1, i)));
    if (worst > 0) uc = mat.law.delta0() / worst;
  }
  if (mat.rodsBreakable && m.numBeams() > 0) {
    std::vector<double> ratio;
    computeStressRatiosForBeams(m, mat, q1, beamBroken, ratio);
    const double worst = *std::max_element(ratio.begin(), ratio.end());
    if (worst > 0 && 1.0 / worst < uc) {
      uc = 1.0 / worst;
      limitedByRod = true;
    }
  }
  return uc;
}

void setQuasiStaticState(const Operators& ops, const Loading& loading, const VecX& q1, const VecX& reaction1,
                         double U, double t, State& s) {
  const double V = loading.velocity(t);
  s.time = t;
  s.loadingTime = t;  // the loading clock (adaptive rate) starts where the loading is, at phi = 1
  s.appliedDisplacement = U;
  s.q = U * q1;
  s.v = V * q1;
  s.a = loading.acceleration(t) * q1;
  s.reaction = U * reaction1;
  double power = 0;
  for (std::size_t i = 0; i < ops.prescribedDofs.size(); ++i) power += s.reaction[i] * ops.prescribedShape[i] * V;
  s.lastExternalPower = power;
}

}  // namespace enamel
