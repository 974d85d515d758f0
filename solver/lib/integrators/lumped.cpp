// Scheme `lumped` (ours, docs/solver.md): explicit central differences with a diagonal mass. Its set-up (the
// rotary-inertia scale, omega_max, dt) and its step; the node rows it calls per slice are node_rows.cpp, the ring
// of slice outputs slice_outputs.hpp.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#if defined(_OPENMP)
#include <omp.h>
#endif

#include "integrators/node_rows.hpp"
#include "integrators/rod_damping.hpp"
#include "integrators/schemes.hpp"
#include "integrators/slice_outputs.hpp"
#include "integrators/step_parts.hpp"
#include "kernels/kernels.hpp"

namespace enamel {

namespace {

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

// Largest frequency of the assembled undamped system M^-1 (K + K_iface) with a diagonal mass (M^-1 K_iface
// without the rods: withRods false), by power iteration (prescribed DOFs held). Interfaces enter through their
// elastic force at a small amplitude (the law is linear below delta0, contact included), never assembled.
double estimateOmegaMax(const CaseParams& p, const Model& m, const cohesive::Law& law, const Operators& ops,
                        const VecX& invMass, bool withRods) {
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
    if (withRods) f += ops.K * x;
    y = invMass.cwiseProduct(f);
    for (int dof : ops.prescribedDofs) y[dof] = 0;
    const double next = x.dot(y.cwiseQuotient(invMass)) / x.dot(x.cwiseQuotient(invMass));
    x = y;
    if (it > 20 && std::abs(next - lambda) < 1e-6 * next) { lambda = next; break; }
    lambda = next;
  }
  return std::sqrt(std::max(lambda, 0.0));
}

// What the node pass's position update moved: the largest |q_i| after it (the largest |dt v_i| is kept per slice).
struct PositionMove {
  double largestValue = 0;
};

// The wrench of a slice whose interfaces the law did not see (all elastic: their forces are in K_I q).
alignas(16) constexpr double kNoWrench[6] = {0, 0, 0, 0, 0, 0};

// Fast scheme `lumped` (ours, docs/solver.md): explicit central differences with a diagonal mass.
//   M: lumped rod mass, translations rho A L / 2 per element end; rotations an isotropic rotary inertia
//      alpha rho Ip L / 2 per element end, alpha the smallest scale at which rotations stop governing.
//   C = a M + b K, the paper's Rayleigh damping. rod_damping = implicit (default): the rods' b K at v_{n+1/2},
//      solved rod by rod (rod_damping.hpp: s M + dt b K is block tridiagonal along each rod), which no step
//      size makes unstable. rod_damping = capped: b' K at v_{n-1/2}, explicit, b' = min(b, c/omega_max),
//      c = damping_cap (the stiffness part's damping ratio at omega_max at most c/2).
//   dt = dt_factor x 2 pi / omega_max (the smallest period of this system), refused above the limit
//   2 / omega_max (sqrt(1 + xi^2) - xi), xi = a / (2 omega_max) (+ b' omega_max / 2 when capped).
//   step_rule = interfaces (implicit only): omega_max that of M^-1 K_I alone and the rotary inertia physical. The
//   step is then stable when M - dt^2/4 K_I > 0 and dt <= 2 b: implicit b K adds dt/2 b K to the mass of the
//   step's stability form M + dt/2 C - dt^2/4 (K + K_I), which covers the rods' dt^2/4 K.
// One step, from q_n and the half-step velocity v_{n-1/2} (State::vHalf), forces first (as written for capped;
// implicit: b' = 0 in the pass, then solveRodDampingOfStep below):
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
// rod_damping = implicit: the pass gives v* (b' = 0) and leaves q_n in place; then
//   (s M + dt b K) v_{n+1/2} = s M v*  (free rows; s = 1 + a dt/2; the grips' v given)   (rods' damping)
//   q_{n+1} = q_n + dt v_{n+1/2}
//   R_p += b (K v_{n+1/2})_p;  W_damp += dt v_{n+1/2} . (a M v_{n+1/2} + b K v_{n+1/2}), where on a free row
//   dt b (K v_{n+1/2})_f = s m_f (v*_f - v_{n+1/2,f})
class LumpedIntegrator : public Integrator {
 public:
  LumpedIntegrator(const CaseParams& p, const Model& m, const Materials& mat, const Operators& ops)
      : dampA_(mat.dampA) {
    const double L = m.beamLength;
    implicit_ = p.rod_damping == RodDamping::implicit;
    interfaceStep_ = p.step_rule == StepRule::interfaces;
    if (interfaceStep_ && !implicit_)
      throw IntegratorError("step_rule = \"interfaces\" needs rod_damping = \"implicit\": only the rods' implicit "
                            "b K keeps their own faster modes stable at the interfaces' step");
    rotaryScale_ = interfaceStep_ ? 1.0 : rotaryScaleForTranslationalLimit(mat.section, L);
    rows_.K = toNodeBlocks(SpMatRow(ops.K));
    rows_.KI = elasticInterfaceBlocks(m, mat.law, ops);
    if (cpuHasAvx512()) rows_.KIocts = octsOfSplit(rows_.KI.split);  // empty where K_I is not split
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
    classifyNodeMasses(mass_, invMass_, m.numNodes(), rows_);
    sliceReach_ = std::max(sliceReach(m, rows_.K), sliceReach(m, rows_.KI));
    rows_.gripOfDof.assign(m.numDofs(), -1);
    rows_.nodeHasGrip.assign(m.numNodes(), 0);
    for (std::size_t i = 0; i < ops.prescribedDofs.size(); ++i) {
      rows_.gripOfDof[ops.prescribedDofs[i]] = static_cast<int>(i);
      rows_.nodeHasGrip[ops.prescribedDofs[i] / 6] = 1;
    }
    rows_.gripResidual = VecX::Zero(static_cast<Eigen::Index>(ops.prescribedDofs.size()));
    for (double shape : ops.prescribedShape) largestShape_ = std::max(largestShape_, std::abs(shape));
    omegaMax_ = estimateOmegaMax(p, m, mat.law, ops, invMass_, !interfaceStep_);
    bEff_ = implicit_ ? mat.dampB : std::min(mat.dampB, p.damping_cap / omegaMax_);
    dt_ = p.dt_factor * 2.0 * M_PI / omegaMax_;
    const double xi = (implicit_ ? 0.0 : 0.5 * bEff_ * omegaMax_) + 0.5 * mat.dampA / omegaMax_;
    const double limit = 2.0 / omegaMax_ * (std::sqrt(1.0 + xi * xi) - xi);
    if (dt_ > 0.95 * limit) {
      std::ostringstream msg;
      msg << "time step dt = " << dt_ << " (dt_factor " << p.dt_factor
          << " x smallest period 2 pi/omega_max of the lumped system) is above the stable limit 0.95 x "
          << limit << " (omega_max = " << omegaMax_ << ", damping ratio there " << xi
          << "): use dt_factor <= " << 0.95 * limit * omegaMax_ / (2 * M_PI);
      throw IntegratorError(msg.str());
    }
    if (interfaceStep_ && dt_ > 2.0 * bEff_) {
      std::ostringstream msg;
      msg << "time step dt = " << dt_ << " is above 2 b = " << 2.0 * bEff_
          << ", where the rods' implicit damping stops covering their stiffness (step_rule = \"interfaces\"): "
             "use dt_factor <= "
          << 2.0 * bEff_ * omegaMax_ / (2 * M_PI);
      throw IntegratorError(msg.str());
    }
    if (implicit_) {
      rodSolve_ = factoriseRodDamping(ops.K, mass_, ops.prescribedDofs, m.nodeRod, 1.0 + 0.5 * dampA_ * dt_,
                                      dt_ * bEff_);
    }
  }

  std::string name() const override { return nameOf(IntegratorScheme::lumped); }
  double timeStep() const override { return dt_; }
  bool usesConsistentMass() const override { return false; }
  bool usesHalfStepVelocity() const override { return true; }
  double addedRotaryInertia() const override { return rotaryScale_ - 1.0; }
  std::string describe() const override {
    std::ostringstream o;
    o << "lumped mass, rotary inertia x " << rotaryScale_ << (interfaceStep_ ? ", omega_max of the interfaces " : ", omega_max ")
      << omegaMax_
      << (implicit_ ? ", stiffness damping b K implicit rod by rod, b " : ", stiffness damping capped, b' ") << bEff_
      << (implicit_ ? " (" + std::to_string(rodSolve_.factors.size()) + " distinct node factors)" : std::string())
      << ", " << rows_.K.values.size() / 36
      << " distinct 6x6 stiffness blocks" << (rows_.K.split.empty() ? "" : " (in-plane and out-of-plane DOFs uncoupled: 18 entries each)")
      << ", elastic interfaces in " << rows_.KI.values.size() / 36 << " distinct 6x6 blocks (18 entries each), node rows "
      << nodeRowsTarget(rows_);
    return o.str();
  }

  // The step as the class comment lists it; each lap books the calls before it to their phase (step_timers.hpp).
  void advance(const Model& m, const Materials& mat, const Operators& ops, State& s) override {
    PhaseLaps laps(timers_);
    gatherGrips(ops, s.vHalf, vGripBefore_);  // v_{n-1/2} of the grips, for their reactions
    laps.lap(StepPhase::GripsAndWork);
    advanceInterfaceSchedule(m, mat.law, ops, moveBound_, sliceMoveBound_, largestValue_, ifaceSchedule_);
    laps.lap(StepPhase::InterfaceSchedule);
    s.failedInterfaces = computeForcesAndAdvanceVelocities(m, mat, ops, s);
    laps.lap(StepPhase::SlicePass);
    if (implicit_) solveRodDampingOfStep(m, ops, s);
    laps.lap(StepPhase::RodDamping);
    computeReactions(ops, s);
    addWorkOfGrips(s, computeGripPower(s.reaction, vGrip_), dt_, s.step > 0);
    addDampingWork(s);
    laps.lap(StepPhase::GripsAndWork);
    const PositionMove move = moveOfStep();
    advanceClock(mat.loading, s, dt_);
    const double Ubefore = s.appliedDisplacement;
    prescribeDisplacements(ops, mat.loading, s);
    moveBound_ = boundMovesOfSlices(move, Ubefore, s.appliedDisplacement);
    largestValue_ = std::max(move.largestValue, largestShape_ * std::abs(s.appliedDisplacement));  // >= max |q_{n+1}|
    laps.lap(StepPhase::ClockAndGrips);
  }

  double lastStepMoveBound() const override { return moveBound_; }
  const std::vector<double>& lastStepMoveBoundsOfSlices() const override { return sliceMoveBound_; }
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
    rows_.K = toNodeBlocks(SpMatRow(ops.K));
    if (implicit_) refactoriseRodDamping(ops.K, mass_, ops.prescribedDofs, rodSolve_);
  }

  double kineticEnergy(const Operators&, const State& s) const override {
    return 0.5 * s.vHalf.dot(mass_.cwiseProduct(s.vHalf));
  }
  double kineticEnergyBeyond(const Operators&, const State& s, double rate) const override {
    const VecX w = s.vHalf - rate * s.q;
    return 0.5 * w.dot(mass_.cwiseProduct(w));
  }
  double addToFreeVelocities(const Operators& ops, State& s, double c) const override {
    double added = 0;
    for (int dof : ops.freeDofs) {
      const double dv = c * s.q[dof];
      added += mass_[dof] * dv * (s.vHalf[dof] + 0.5 * dv);
      s.vHalf[dof] += dv;
    }
    return added;
  }

 private:
  // Forces, then velocities, slice by slice in one pass over the model (its slices in parallel; within a
  // slice in a fixed order, so nothing depends on the thread count). Per slice:
  //   the wrench W of its interfaces on its nodes beyond their elastic force: the law's (opening, law, force
  //     on B) of those the schedule (InterfaceSchedule, kernels.hpp; advanced for this step) makes due, their
  //     history updated at q_n, less the elastic force of those off the elastic branch
  //   per node: K_I q_n (its block row; all the slice's nodes first), then (advanceNode) K q_n and K v_{n-1/2}
  //     (its block rows), r = K q + K_I q - W + b' K v,
  //     v_{n+1/2} = [(1 - a dt/2) v_{n-1/2} - dt M^-1 r] / (1 + a dt/2), and for the grips
  //     v_{n+1/2} = shape V(t_n + dt/2) and r kept for their reactions
  //   the slice's share of the damping work's sums v.Mv and v.Kv_{n-1/2}
  //   q_{n+1} = q_n + dt v_{n+1/2}, and the slice's share of its maxima max |dt v|, max |q_{n+1}|
  // v_{n+1/2} and q_{n+1} replace v_{n-1/2} and q_n in place once no slice still to come reads them
  // (SliceOutputs: a slice's rows reach sliceReach_ slices either side; each thread takes one run of
  // consecutive slices, and those its neighbours read wait for the end of the pass). Returns the number of
  // failed interfaces. With timers, each thread laps its slices' phases and books its share, 1 / threads.
  [[gnu::flatten]] int computeForcesAndAdvanceVelocities(const Model& m, const Materials& mat, const Operators& ops, State& s) {
    const cohesive::Law law = mat.law;
    NodeStep step;
    step.keep = 1.0 - 0.5 * dampA_ * dt_;
    step.scale = 1.0 + 0.5 * dampA_ * dt_;
    step.dt = dt_;
    step.b = implicit_ ? 0.0 : bEff_;
    step.move = implicit_ ? 0.0 : dt_;
    step.Vgrip = computeGripVelocity(mat.loading, s, 0.5 * dt_, dt_);
    vNext_.resize(s.vHalf.size());
    qNext_.resize(s.q.size());
    sliceSums_.assign(m.numSlices, SliceSums{});
    const double* q = s.q.data();
    const double* v = s.vHalf.data();
    double* lambda = s.lambdaMax.data();
    int failed = 0;
    long evaluated = 0, chunks = 0;
#pragma omp parallel reduction(+ : failed, evaluated, chunks) firstprivate(law, q, v, lambda, step)
    {
      std::vector<double> wrench(6 * static_cast<std::size_t>(ops.maxNodesPerSlice));
      std::vector<DoublePair> KIq(3 * static_cast<std::size_t>(ops.maxNodesPerSlice));  // the slice's K_I q_n
      SliceOutputs out(ops, s, m.numSlices, sliceReach_, vNext_.data(), qNext_.data());
      StepTimers mine;
      PhaseLaps laps(timers_ ? &mine : nullptr);
      for (int k = out.first; k < out.last; ++k) {
        const SliceCorrections pass =
            addInterfaceCorrectionsOfSliceScheduled(m, law, ops, k, q, lambda, ifaceSchedule_, wrench.data(), evaluated);
        failed += pass.failed;
        chunks += pass.chunks;
        laps.lap(StepPhase::SliceInterfaces);
        const SliceOutputs::Slot to = out.slotOf(k);
        // no wrench written: every node reads the same six zeros
        sliceSums_[k] = pass.wrench ? advanceNodesOfSlice(rows_, ops, step, k, q, v, wrench.data(), 6, KIq.data(), to.v, to.q)
                                    : advanceNodesOfSlice(rows_, ops, step, k, q, v, kNoWrench, 0, KIq.data(), to.v, to.q);
        laps.lap(StepPhase::SliceNodes);
        out.replaceBefore(k);
        laps.lap(StepPhase::SliceWrites);
      }
#pragma omp barrier
      laps.lap(StepPhase::SliceBarrier);
      out.replaceWaiting();
      laps.lap(StepPhase::SliceWrites);
      if (timers_) bookShareOfThread(mine);
    }
    ifaceSchedule_.evaluated = evaluated;
    ifaceSchedule_.visitedChunks = chunks;
    return failed;
  }

  // timers_ += this thread's seconds / the pass's threads (its laps in full), one thread at a time
  void bookShareOfThread(const StepTimers& mine) {
#if defined(_OPENMP)
    const double share = 1.0 / omp_get_num_threads();
#else
    const double share = 1.0;
#endif
#pragma omp critical(enamel_step_timers)
    addShareOfTimers(mine, share, *timers_);
  }

  // The rods' damping, implicit (the class comment): v_{n+1/2} from the pass's v* (the pass left q_n in place);
  // then slice by slice q_{n+1} = q_n + dt v_{n+1/2} and the slice's sums: max |dt v|, max |q|, v.Mv and v.Kv (on
  // a free row from the solve's identity dt b (K v)_f = s m_f (v*_f - v_f); on a grip's v* = v, and its v.Kv from
  // its row of K); the grips' b K v into their residuals.
  void solveRodDampingOfStep(const Model& m, const Operators& ops, State& s) {
    std::swap(s.vHalf, vStar_);  // v* (the pass's) kept; s.vHalf becomes the solve's output
    s.vHalf.resize(vStar_.size());
    solveRodDamping(rodSolve_, vStar_, s.vHalf);
    const int slices = static_cast<int>(sliceSums_.size());
    const double cInv = 1.0 / rodSolve_.c, dt = dt_;
    double* q = s.q.data();
    const double *v = s.vHalf.data(), *vStar = vStar_.data(), *mass = mass_.data(), *scale = rodSolve_.rhsScale.data();
#pragma omp parallel for schedule(static)
    for (int k = 0; k < slices; ++k) {
      double largestStep = 0, largestValue = 0, workM = 0, workK = 0;
      for (int dof = 6 * ops.sliceNodeStart[k]; dof < 6 * ops.sliceNodeStart[k + 1]; ++dof) {
        const double step = dt * v[dof], y = q[dof] + step;
        q[dof] = y;
        largestStep = std::max(largestStep, std::abs(step)), largestValue = std::max(largestValue, std::abs(y));
        workM += v[dof] * mass[dof] * v[dof];
        workK += v[dof] * scale[dof] * (vStar[dof] - v[dof]);
      }
      SliceSums& out = sliceSums_[k];
      out.largestStep = DoublePair{largestStep, 0}, out.largestValue = DoublePair{largestValue, 0};
      out.workM = DoublePair{workM, 0}, out.workK = DoublePair{workK * cInv, 0};
    }
    multiplyGripRows(rodSolve_, s.vHalf, KvGrip_);
    for (std::size_t i = 0; i < ops.prescribedDofs.size(); ++i) {
      rows_.gripResidual[i] += bEff_ * KvGrip_[i];
      sliceSums_[m.nodeSlice[ops.prescribedDofs[i] / 6]].workK[1] += s.vHalf[ops.prescribedDofs[i]] * KvGrip_[i];
    }
  }

  // R_p = K q + f_iface + b' K v_{n-1/2} + m_p (a_p + a v_p) at t_n, with
  // a_p = (v_{n+1/2} - v_{n-1/2}) / dt and v_p = (v_{n+1/2} + v_{n-1/2}) / 2 (kept in vGrip_)
  void computeReactions(const Operators& ops, State& s) {
    vGrip_.resize(vGripBefore_.size());
    for (std::size_t i = 0; i < ops.prescribedDofs.size(); ++i) {
      const int dof = ops.prescribedDofs[i];
      const double acc = (s.vHalf[dof] - vGripBefore_[i]) / dt_, vel = 0.5 * (s.vHalf[dof] + vGripBefore_[i]);
      s.reaction[i] = rows_.gripResidual[i] + mass_[dof] * (acc + dampA_ * vel);
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
    for (const SliceSums& k : sliceSums_)  // maxima: exact in any order
      move.largestValue = std::max({move.largestValue, k.largestValue[0], k.largestValue[1]});
    return move;
  }

  // Per slice k, max_i |q_{n+1,i} - q_{n,i}| over its DOFs (into sliceMoveBound_), and returned the largest of
  // them, the bound over all DOFs (rounding is monotone, so it equals the same formula on the maxima over slices):
  // a free DOF moved by fl(q + dt v) - q, at most |dt v| plus half an ulp of the result; a grip by
  // shape (U_{n+1} - U_n) plus the round-off of both products (every grip's, wherever it is). So the larger of the
  // slice's largest |dt v| and the grips' move, plus 2^-52 of the largest |q| anywhere (an ulp), with a relative
  // 1e-12 for the products.
  double boundMovesOfSlices(const PositionMove& move, double Ubefore, double Uafter) {
    const double grips = largestShape_ * std::abs(Uafter - Ubefore);
    const double largest = std::max({move.largestValue, largestShape_ * std::abs(Uafter), largestShape_ * std::abs(Ubefore)});
    sliceMoveBound_.resize(sliceSums_.size());
    double bound = 0;
    for (std::size_t k = 0; k < sliceSums_.size(); ++k) {
      const double step = std::max(sliceSums_[k].largestStep[0], sliceSums_[k].largestStep[1]);
      sliceMoveBound_[k] = std::max(step, grips) * (1.0 + 1e-12) + std::ldexp(largest, -52);
      bound = std::max(bound, sliceMoveBound_[k]);
    }
    return bound;
  }

  double dt_ = 0, rotaryScale_ = 1, omegaMax_ = 0, bEff_ = 0, dampA_ = 0;
  bool implicit_ = true;             // rod_damping = implicit: the rods' b K solved at each step
  bool interfaceStep_ = false;       // step_rule = interfaces: omega_max of M^-1 K_I, physical rotary inertia
  RodDampingSolve rodSolve_;         // its factors (rod_damping.hpp)
  VecX vStar_, KvGrip_;              // the pass's v*, and the grips' rows of K v_{n+1/2}
  double largestShape_ = 0;          // max |shape| of the prescribed DOFs
  double moveBound_ = INFINITY;      // lastStepMoveBound (infinite: q was set otherwise, the schedules start afresh)
  double largestValue_ = INFINITY;   // a bound on max |q_n|
  std::vector<double> sliceMoveBound_;  // lastStepMoveBoundsOfSlices: per slice, the move bound of its DOFs
  InterfaceSchedule ifaceSchedule_;  // which interfaces the law must see (kernels.hpp)
  VecX mass_, invMass_, fI_, vNext_, qNext_, vGripBefore_, vGrip_;
  std::vector<SliceSums> sliceSums_;  // per slice
  NodeRows rows_;                     // K and K_I in node blocks, the node masses, the grips (node_rows.hpp)
  int sliceReach_ = 1;                // how many slices either side a node's rows read (SliceOutputs)
};

}  // namespace

std::unique_ptr<Integrator> makeLumpedIntegrator(const CaseParams& p, const Model& m, const Materials& mat,
                                                 const Operators& ops) {
  return std::make_unique<LumpedIntegrator>(p, m, mat, ops);
}

}  // namespace enamel
