// The kernels on a small model (kernels.hpp): the per-node gather of interface forces is the sum of the
// tested pointwise function cohesive::computeInterfaceForces, and errors map to their exit statuses (a failed
// factorisation is a failed run, 11; a refused time step is bad input, 7); the inverse of the loading and the
// static elastic start (case key static_start).
#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "base/exit_codes.hpp"
#include "kernels/kernels.hpp"
#include "kernels/node_blocks.hpp"
#include "kernels/static_solve.hpp"
#include "run/runner.hpp"
#include "simulation/simulation.hpp"

using namespace enamel;

namespace {

// 8 d wide, `height` d high (4: one chunk of interfaces per slice, InterfaceSchedule; 16: two or more).
CaseParams smallCase(const std::string& extra, int height = 4) {
  // E_transverse given (not measured) to keep the set-up short.
  return parseCase("theta_D = 30\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\nE_transverse_over_Er = 0.1\n"
                   "w_s_over_d = 8\nh_s_over_d = " + std::to_string(height) + "\n" + extra,
                   "kernels", "", {});
}

// A deterministic field of amplitude `amp` on every DOF.
VecX pseudoRandomField(int n, double amp) {
  VecX q(n);
  std::uint64_t seed = 7;
  for (int i = 0; i < n; ++i) {
    seed = seed * 6364136223846793005ULL + 1442695040888963407ULL;
    q[i] = amp * (static_cast<double>(seed >> 11) / 9007199254740992.0 - 0.5);
  }
  return q;
}

// f_iface as the lumped step applies it: K_I q (elasticInterfaceBlocks, in its node rows) less, per slice, the
// wrench W of its interfaces beyond their elastic force (addInterfaceCorrectionsOfSliceScheduled, the call the
// step makes per slice; nothing where it wrote none), the slices in parallel. schedule.evaluated: the interfaces
// the law saw; schedule.visitedChunks: the chunks of interfaces read. Returns the number of failed interfaces.
int scheduledInterfaceForces(const Model& m, const cohesive::Law& law, const Operators& ops, const NodeBlockMatrix& KI,
                             const VecX& q, std::vector<double>& lambdaMax, InterfaceSchedule& schedule, VecX& f) {
  f.resize(m.numDofs());
  int failed = 0;
  long evaluated = 0, chunks = 0;
#pragma omp parallel reduction(+ : failed, evaluated, chunks)
  {
    std::vector<double> wrench(6 * static_cast<std::size_t>(ops.maxNodesPerSlice));
#pragma omp for schedule(static)
    for (int k = 0; k < m.numSlices; ++k) {
      const SliceCorrections pass = addInterfaceCorrectionsOfSliceScheduled(m, law, ops, k, q.data(), lambdaMax.data(),
                                                                            schedule, wrench.data(), evaluated);
      failed += pass.failed;
      chunks += pass.chunks;
      for (int node = ops.sliceNodeStart[k]; node < ops.sliceNodeStart[k + 1]; ++node) {
        Vec6 elastic;
        multiplyBlockRowSplit<kInterfaceGroups>(KI, node, q.data(), elastic);
        const double* W = wrench.data() + 6 * (node - ops.sliceNodeStart[k]);
        for (int j = 0; j < 6; ++j) f[6 * node + j] = pass.wrench ? elastic[j] - W[j] : elastic[j];
      }
    }
  }
  schedule.evaluated = evaluated;
  schedule.visitedChunks = chunks;
  return failed;
}

// Per slice, the largest |change| of its nodes' DOFs, as a move bound (x (1 + 1e-12) + 1e-300).
std::vector<double> movesOfSlices(const Model& m, const VecX& change) {
  std::vector<double> moved(m.numSlices, 0.0);
  for (int node = 0; node < m.numNodes(); ++node)
    for (int j = 0; j < 6; ++j) {
      double& slice = moved[m.nodeSlice[node]];
      slice = std::max(slice, std::abs(change[6 * node + j]));
    }
  for (double& x : moved) x = x * (1 + 1e-12) + 1e-300;
  return moved;
}

// `field` scaled node by node by 0.25 + 0.75 x (its slice / the last slice): slices that move at different speeds.
VecX rampedAlongSlices(const Model& m, const VecX& field) {
  VecX out = field;
  for (int node = 0; node < m.numNodes(); ++node)
    out.segment<6>(6 * node) *= 0.25 + 0.75 * m.nodeSlice[node] / std::max(1.0, m.numSlices - 1.0);
  return out;
}

}  // namespace

// f_iface from the gather against the nodal wrenches of computeInterfaceForces summed interface by
// interface. The sums run in different orders, so they agree to round-off: 1e-12 of the largest force.
// The amplitude (3 x delta0) takes interfaces past the elastic range, so the history matters.
TEST(Kernels, InterfaceGatherSumsComputeInterfaceForces) {
  Simulation sim(smallCase("integrator = \"lumped\"\n"));
  const Model& m = sim.model;
  const cohesive::Law& law = sim.materials.law;
  const VecX q = pseudoRandomField(m.numDofs(), 3 * law.delta0());
  std::vector<double> lambdaMax(m.numInterfaces(), 0.0);
  VecX f(m.numDofs());
  const int failed = computeForcesForInterfaces(m, law, sim.ops, q, lambdaMax, true, f);

  VecX expected = VecX::Zero(m.numDofs());
  std::vector<double> lambdaExpected(m.numInterfaces(), 0.0);
  int failedExpected = 0, inelastic = 0;
  for (int i = 0; i < m.numInterfaces(); ++i) {
    const int A = m.ifaceNodes[i][0], B = m.ifaceNodes[i][1];
    const cohesive::NodalWrench w = cohesive::computeInterfaceForces(
        law, m.ifaceGeom[i], q.segment<3>(6 * A), q.segment<3>(6 * A + 3), q.segment<3>(6 * B),
        q.segment<3>(6 * B + 3), lambdaExpected[i]);
    expected.segment<3>(6 * A) -= w.forceA;
    expected.segment<3>(6 * A + 3) -= w.momentA;
    expected.segment<3>(6 * B) -= w.forceB;
    expected.segment<3>(6 * B + 3) -= w.momentB;
    failedExpected += cohesive::isFailed(law, lambdaExpected[i]);
    inelastic += cohesive::isInelastic(law, lambdaExpected[i]);
  }
  ASSERT_GT(inelastic, 0) << "the field should take some interfaces past delta0";
  EXPECT_LE((f - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());
  EXPECT_EQ(failed, failedExpected);
  for (int i = 0; i < m.numInterfaces(); ++i) ASSERT_EQ(lambdaMax[i], lambdaExpected[i]) << "interface " << i;

  // a trial evaluation (update = false) leaves the history as it was
  const std::vector<double> before = lambdaMax;
  computeForcesForInterfaces(m, law, sim.ops, 2.0 * q, lambdaMax, false, f);
  EXPECT_EQ(lambdaMax, before);
}

// A factorisation that fails (H = M + dt/2 C made negative definite) throws SolverError, whose exit status
// is run_failed (11), not out_of_range (7).
// The scheduled deletion check (StressCheckSchedule) against the check of every element, along a path of
// displacements that loads rods past their strength, its slices moving at different speeds: at every step the
// same elements are at or above 1 - margin with the same ratios bit for bit (so the same ones break; the
// schedule's largest ratio reaches 1 at the same steps as the full check's largest and then equals it), while
// most steps compute only a few elements; a step that moved further than the scheme says would be unsafe, so a
// jump (q replaced) must be given as an infinite move, and then every element is computed. `perSlice`: each
// slice's own move is given (each element follows its pair of slices), otherwise only the largest.
static void checkScheduledStressCheckFindsWhatTheFullCheckFinds(bool perSlice, long& computed, int height = 4) {
  Simulation sim(smallCase("integrator = \"lumped\"\n", height));
  const Model& m = sim.model;
  const Materials& mat = sim.materials;
  const std::vector<std::uint8_t> broken(m.numBeams(), 0);
  const VecX shape = rampedAlongSlices(m, pseudoRandomField(m.numDofs(), 1.0));
  // the amplitude at which the most stressed element of `shape` reaches its strength
  std::vector<double> full;
  computeStressRatiosForBeams(m, mat, shape, broken, full);
  const double unitRatio = *std::max_element(full.begin(), full.end());
  ASSERT_GT(unitRatio, 0.0);
  StressCheckSchedule schedule;
  std::vector<double> scheduled;
  const int steps = 400;
  computed = 0;
  int overloadedSteps = 0;
  VecX qPrev = VecX::Zero(m.numDofs());
  for (int n = 1; n <= steps; ++n) {
    const VecX q = (1.2 * n / steps / unitRatio) * shape;  // passes ratio 1 at step ~333
    const double moved = (q - qPrev).cwiseAbs().maxCoeff();
    const std::vector<double> sliceMoved = perSlice ? movesOfSlices(m, q - qPrev) : std::vector<double>{};
    checkStressRatiosForBeams(m, mat, q, broken, n, moved, sliceMoved, schedule, scheduled);
    computeStressRatiosForBeams(m, mat, q, broken, full);
    computed += schedule.computed;
    bool anyOverloaded = false;
    for (int e = 0; e < m.numBeams(); ++e) {
      if (full[e] >= 1.0 - kStressScheduleMargin) {
        ASSERT_EQ(scheduled[e], full[e]) << "element " << e << " at step " << n;
        anyOverloaded = anyOverloaded || full[e] >= 1.0;
      } else {
        ASSERT_LT(scheduled[e], 1.0 - kStressScheduleMargin) << "element " << e << " at step " << n;
      }
    }
    overloadedSteps += anyOverloaded;
    // the largest ratio reaches 1 exactly when some element's does (the step then looks for them)
    const double largestFull = *std::max_element(full.begin(), full.end());
    ASSERT_EQ(schedule.largestRatio >= 1.0, anyOverloaded) << "step " << n;
    if (anyOverloaded) ASSERT_EQ(schedule.largestRatio, largestFull) << "step " << n;
    qPrev = q;
  }
  EXPECT_GT(overloadedSteps, 0);
  EXPECT_LT(computed, static_cast<long>(steps) * m.numBeams() / 4) << "the schedule skips most computations";
  // a jump given as infinite: every element computed, and equal to the full check
  const VecX jump = (0.5 / unitRatio) * shape;
  checkStressRatiosForBeams(m, mat, jump, broken, steps + 1, INFINITY, {}, schedule, scheduled);
  computeStressRatiosForBeams(m, mat, jump, broken, full);
  EXPECT_EQ(schedule.computed, m.numBeams());
  // every chunk read, not the last scheduled check's count
  EXPECT_EQ(schedule.visitedChunks, (m.numBeams() + kStressCheckChunk - 1) / kStressCheckChunk);
  EXPECT_EQ(scheduled, full);
  // after it the schedule starts afresh (all), then skips (nothing moved); a check that is not the next
  // step's starts afresh again
  checkStressRatiosForBeams(m, mat, jump, broken, steps + 2, 0.0, {}, schedule, scheduled);
  EXPECT_EQ(schedule.computed, m.numBeams());
  checkStressRatiosForBeams(m, mat, jump, broken, steps + 3, 0.0, {}, schedule, scheduled);
  EXPECT_LT(schedule.computed, m.numBeams() / 4);
  checkStressRatiosForBeams(m, mat, jump, broken, steps + 9, 0.0, {}, schedule, scheduled);
  EXPECT_EQ(schedule.computed, m.numBeams());
  EXPECT_EQ(scheduled, full);
}

TEST(Kernels, ScheduledStressCheckFindsWhatTheFullCheckFinds) {
  long global = 0, perSlice = 0;
  checkScheduledStressCheckFindsWhatTheFullCheckFinds(false, global);
  checkScheduledStressCheckFindsWhatTheFullCheckFinds(true, perSlice);
  EXPECT_LT(perSlice, global) << "slices that move less are computed less often";
  checkScheduledStressCheckFindsWhatTheFullCheckFinds(true, perSlice, 16);  // more chunks of elements per pair
}

// Each element follows the drift of its own two slices: when only the nodes of one slice move, only the elements
// that reach that slice are ever computed (after the fresh start), however far it moves, and only the chunks of
// elements (StressCheckSchedule::chunkDue) that hold one of them are read; given only the largest move, elements
// everywhere come due.
TEST(Kernels, ScheduledStressCheckFollowsEachSlicesMove) {
  Simulation sim(smallCase("integrator = \"lumped\"\n", 16));
  const Model& m = sim.model;
  const Materials& mat = sim.materials;
  const std::vector<std::uint8_t> broken(m.numBeams(), 0);
  const VecX shape = pseudoRandomField(m.numDofs(), 1.0);
  std::vector<double> full;
  computeStressRatiosForBeams(m, mat, shape, broken, full);
  const double unitRatio = *std::max_element(full.begin(), full.end());
  const int moving = m.numSlices / 2;
  VecX wobble = VecX::Zero(m.numDofs());
  for (int node = sim.ops.sliceNodeStart[moving]; node < sim.ops.sliceNodeStart[moving + 1]; ++node)
    wobble.segment<6>(6 * node) = shape.segment<6>(6 * node);
  auto reachesMoving = [&](int e) {
    return m.nodeSlice[m.beamNodes[e][0]] == moving || m.nodeSlice[m.beamNodes[e][1]] == moving;
  };
  const int chunks = (m.numBeams() + kStressCheckChunk - 1) / kStressCheckChunk;
  int chunksReaching = 0;
  for (int c = 0; c < chunks; ++c) {
    bool reaches = false;
    for (int e = c * kStressCheckChunk; e < std::min(m.numBeams(), (c + 1) * kStressCheckChunk); ++e)
      reaches = reaches || reachesMoving(e);
    chunksReaching += reaches;
  }
  ASSERT_LT(chunksReaching, chunks / 4);
  for (bool perSlice : {true, false}) {
    StressCheckSchedule schedule;
    std::vector<double> ratio;
    std::vector<char> everComputed(m.numBeams(), 0);
    VecX qPrev = (0.5 / unitRatio) * shape;
    checkStressRatiosForBeams(m, mat, qPrev, broken, 1, 0.0, {}, schedule, ratio);  // a fresh schedule: all
    for (int n = 2; n <= 200; ++n) {
      const VecX q = (0.5 / unitRatio) * shape + (0.4 / unitRatio) * std::sin(0.1 * n) * wobble;
      std::fill(ratio.begin(), ratio.end(), -1.0);  // an element the check computes gets its ratio, >= 0
      checkStressRatiosForBeams(m, mat, q, broken, n, (q - qPrev).cwiseAbs().maxCoeff() * (1 + 1e-12) + 1e-300,
                                perSlice ? movesOfSlices(m, q - qPrev) : std::vector<double>{}, schedule, ratio);
      if (perSlice) ASSERT_LE(schedule.visitedChunks, chunksReaching) << "step " << n;
      for (int e = 0; e < m.numBeams(); ++e) everComputed[e] |= ratio[e] >= 0;
      qPrev = q;
    }
    int reaching = 0, elsewhere = 0;
    for (int e = 0; e < m.numBeams(); ++e)
      if (everComputed[e]) (reachesMoving(e) ? reaching : elsewhere) += 1;
    EXPECT_GT(reaching, 0) << (perSlice ? "per slice" : "largest move only");
    if (perSlice)
      EXPECT_EQ(elsewhere, 0) << "an element away from the moving slice was computed";
    else
      EXPECT_GT(elsewhere, 0) << "with only the largest move, every element follows it";
  }
}

// The elastic force of an interface (cohesive::elasticForceOnB, what the scheduled pass uses while the secant
// stiffness is k) is the law's force there, tension and compression alike, to round-off; and the compact form's
// pieces give computeInterfaceForceOnB bit for bit.
TEST(Kernels, ElasticInterfaceForceIsTheLawsOnTheElasticBranch) {
  Simulation sim(smallCase("integrator = \"lumped\"\n"));
  const cohesive::Law& law = sim.materials.law;
  const VecX q = pseudoRandomField(sim.model.numDofs(), 0.3 * law.delta0());
  for (int i = 0; i < sim.model.numInterfaces(); ++i) {
    const int A = sim.model.ifaceNodes[i][0], B = sim.model.ifaceNodes[i][1];
    const cohesive::SliceInterface& g = sim.ops.ifacePacked[i];
    const Vec3 uA = q.segment<3>(6 * A), thA = q.segment<3>(6 * A + 3), uB = q.segment<3>(6 * B), thB = q.segment<3>(6 * B + 3);
    double lm = 0.5 * law.delta0(), lmPieces = lm;
    const Vec3 F = cohesive::computeInterfaceForceOnB(law, g, uA, thA, uB, thB, lm);
    ASSERT_EQ(cohesive::secantStiffness(law, lm), law.k);
    const Vec3 E = cohesive::elasticForceOnB(law, g, uA, thA, uB, thB);
    ASSERT_LE((F - E).norm(), 1e-13 * law.k * g.area * law.delta0()) << "interface " << i;
    const Vec3 t = cohesive::computeTraction(law, cohesive::localOpening(g, cohesive::computeOpening(g, uA, thA, uB, thB)), lmPieces);
    ASSERT_EQ(cohesive::forceOnBOfTraction(g, t), F);
    ASSERT_EQ(lmPieces, lm);
  }
}

// The scheduled interface pass (InterfaceSchedule: advanceInterfaceSchedule, then per slice
// addInterfaceCorrectionsOfSliceScheduled and K_I q, as the lumped step calls them) along a path that fails some
// interfaces and comes back: the
// same histories and failed counts as evaluating every interface by the law, forces within round-off of it (and of the elastic blocks' tolerance, kInterfaceBlockTolerance);
// a schedule started afresh part-way (a restart) gives the same forces bit for bit; no thread count matters.
// `keys`: further case keys (the mixed-mode law's shear_strength_ratio, whose lambda weighs shear by 1/beta^2).
// The slices move at different speeds; `perSlice`: each slice's own move is given, otherwise only the largest.
// `evaluated`: the interfaces the law saw, over the path.
static void checkScheduledInterfacePassFollowsTheLaw(const std::string& keys, bool perSlice, long& evaluated,
                                                     int height = 4) {
  Simulation sim(smallCase("integrator = \"lumped\"\n" + keys, height));
  const Model& m = sim.model;
  const cohesive::Law& law = sim.materials.law;
  const int n = m.numDofs();
  const VecX shape = rampedAlongSlices(m, pseudoRandomField(n, 1.0)), wobble = pseudoRandomField(n, 1.0).reverse();
  std::vector<double> lmLaw(m.numInterfaces(), 0.0), lmSched = lmLaw, lmFresh = lmLaw;
  InterfaceSchedule sched, fresh;
  VecX before = VecX::Zero(n), fLaw, fSched, fFresh;
  const NodeBlockMatrix KI = elasticInterfaceBlocks(m, law, sim.ops);
  double elasticScale = 0;  // k A (2 + |arms|): the largest elastic force per unit of max |q|
  for (const auto& g : sim.ops.ifacePacked)
    elasticScale = std::max(elasticScale, law.k * g.area * (2 + std::abs(g.armAy) + std::abs(g.armAz) +
                                                              std::abs(g.armBy) + std::abs(g.armBz)));
  evaluated = 0;
  const int steps = 400, restartAt = 250, threads = omp_get_max_threads();
  for (int t = 0; t <= steps; ++t) {
    const double a = 15.0 * law.delta0() * std::sin(M_PI * t / steps);  // out to 15 delta0 and back
    const VecX q = a * shape + 0.05 * law.delta0() * std::cos(0.3 * t) * wobble;
    const double moved = t == 0 ? INFINITY : (q - before).cwiseAbs().maxCoeff() * (1 + 1e-12) + 1e-300;
    const std::vector<double> sliceMoved = perSlice ? movesOfSlices(m, q - before) : std::vector<double>{};
    before = q;
    omp_set_num_threads(1 + t % 2);
    if (t == restartAt) lmFresh = lmSched;
    const int failedLaw = computeForcesForInterfaces(m, law, sim.ops, q, lmLaw, true, fLaw);
    advanceInterfaceSchedule(m, law, sim.ops, moved, sliceMoved, q.cwiseAbs().maxCoeff(), sched);
    const int failedSched = scheduledInterfaceForces(m, law, sim.ops, KI, q, lmSched, sched, fSched);
    evaluated += sched.evaluated;
    ASSERT_EQ(failedSched, failedLaw) << "step " << t;
    for (int i = 0; i < m.numInterfaces(); ++i) ASSERT_EQ(lmSched[i], lmLaw[i]) << "step " << t << ", interface " << i;
    // K_I's blocks agree with each interface's elastic stiffness to kInterfaceBlockTolerance: an interface off the
    // elastic branch has K_I q (its elastic force, up to that) less its exact elastic force added, so the
    // difference is within that tolerance of the largest elastic force, k A_max |opening|_max.
    ASSERT_LE((fSched - fLaw).cwiseAbs().maxCoeff(),
              1e-12 * fLaw.cwiseAbs().maxCoeff() + 64 * kInterfaceBlockTolerance * elasticScale * q.cwiseAbs().maxCoeff())
        << "step " << t;
    if (t >= restartAt) {  // lmFresh holds the histories before this step's update, as a checkpoint would
      advanceInterfaceSchedule(m, law, sim.ops, t == restartAt ? INFINITY : moved, sliceMoved, q.cwiseAbs().maxCoeff(),
                               fresh);
      scheduledInterfaceForces(m, law, sim.ops, KI, q, lmFresh, fresh, fFresh);
      ASSERT_EQ(fFresh, fSched) << "step " << t;
      ASSERT_EQ(lmFresh, lmSched) << "step " << t;
    }
  }
  omp_set_num_threads(threads);
  int failed = 0;
  for (double lm : lmLaw) failed += cohesive::isFailed(law, lm);
  EXPECT_GT(failed, 0) << "the path should fail some interfaces";
  EXPECT_LT(evaluated, static_cast<long>(steps + 1) * m.numInterfaces()) << "the schedule should skip some";
}

// Per slice the law sees fewer interfaces than with the largest move alone, and follows it all the same.
static void checkScheduledInterfacePassBothWays(const std::string& keys) {
  long global = 0, perSlice = 0;
  checkScheduledInterfacePassFollowsTheLaw(keys, false, global);
  checkScheduledInterfacePassFollowsTheLaw(keys, true, perSlice);
  EXPECT_LT(perSlice, global) << "slices that move less are seen by the law less often";
}

TEST(Kernels, ScheduledInterfacePassFollowsTheLaw) { checkScheduledInterfacePassBothWays(""); }
// Slices of several chunks of interfaces (InterfaceSchedule::chunkDue), some skipped and some read.
TEST(Kernels, ScheduledInterfacePassFollowsTheLawInChunks) {
  long global = 0, perSlice = 0;
  checkScheduledInterfacePassFollowsTheLaw("", false, global, 16);
  checkScheduledInterfacePassFollowsTheLaw("", true, perSlice, 16);
  EXPECT_LT(perSlice, global);
}

// A pass reads only the chunks of interfaces that hold a due one: at rest after a fresh pass (all read) none is
// due and none is read; with one interface due (its due, and so its chunk's smallest, at the drift)
// the law sees it alone and its chunk is the only one read, though its slice has several.
TEST(Kernels, ScheduledInterfacePassReadsOnlyChunksWithADueInterface) {
  Simulation sim(smallCase("integrator = \"lumped\"\n", 16));
  const Model& m = sim.model;
  const cohesive::Law& law = sim.materials.law;
  const NodeBlockMatrix KI = elasticInterfaceBlocks(m, law, sim.ops);
  const VecX q = VecX::Zero(m.numDofs());
  std::vector<double> lambdaMax(m.numInterfaces(), 0.0);
  InterfaceSchedule schedule;
  VecX f;
  advanceInterfaceSchedule(m, law, sim.ops, INFINITY, {}, 0.0, schedule);
  scheduledInterfaceForces(m, law, sim.ops, KI, q, lambdaMax, schedule, f);
  EXPECT_EQ(schedule.evaluated, m.numInterfaces());
  EXPECT_EQ(schedule.visitedChunks, schedule.sliceChunkStart[m.numSlices]);
  advanceInterfaceSchedule(m, law, sim.ops, 0.0, {}, 0.0, schedule);
  scheduledInterfaceForces(m, law, sim.ops, KI, q, lambdaMax, schedule, f);
  EXPECT_EQ(schedule.evaluated, 0);
  EXPECT_EQ(schedule.visitedChunks, 0);
  const int k = m.numSlices / 2, c = schedule.sliceChunkStart[k] + 1;
  ASSERT_GE(schedule.sliceChunkStart[k + 1] - schedule.sliceChunkStart[k], 2) << "a slice of several chunks";
  const int i = sim.ops.sliceIfaceStart[k] + kInterfaceChunk + 3;  // in the slice's second chunk
  schedule.due[i] = schedule.chunkDue[c] = schedule.drift[k];
  advanceInterfaceSchedule(m, law, sim.ops, 0.0, {}, 0.0, schedule);
  scheduledInterfaceForces(m, law, sim.ops, KI, q, lambdaMax, schedule, f);
  EXPECT_EQ(schedule.evaluated, 1);
  EXPECT_EQ(schedule.visitedChunks, 1);
  EXPECT_GT(schedule.chunkDue[c], schedule.drift[k]) << "evaluated, it is not due again at once";
}
// A weak shear (beta < 1) makes lambda grow faster than the opening's norm: the schedule must bound that.
TEST(Kernels, ScheduledInterfacePassFollowsTheMixedModeLawWeakShear) {
  checkScheduledInterfacePassBothWays("shear_strength_ratio = 0.5\n");
}
TEST(Kernels, ScheduledInterfacePassFollowsTheMixedModeLawStrongShear) {
  checkScheduledInterfacePassBothWays("shear_strength_ratio = 2\n");
}

// K in node blocks (node_blocks.hpp) against Eigen's sparse product: the rods lie in xy-planes, so the model's
// K splits into in-plane and out-of-plane DOFs, and the 18-entry product gives the general 36-entry one bit for
// bit (the sign of a zero aside, which == ignores), both within round-off of K x; a K that couples the groups
// gets no split form.
TEST(Kernels, NodeBlockProductsEqualTheSparseProduct) {
  Simulation sim(smallCase("integrator = \"lumped\"\n"));
  const NodeBlockMatrix K = toNodeBlocks(SpMatRow(sim.ops.K));
  ASSERT_FALSE(K.split.empty());
  const int n = sim.model.numDofs();
  const VecX x1 = pseudoRandomField(n, 1.0), x2 = pseudoRandomField(n, 1.0).reverse();
  const VecX Kx1 = sim.ops.K * x1;
  for (int R = 0; R < K.blockRows; ++R) {
    Vec6 a1, a2, b1, b2;
    multiplyBlockRow(K, R, x1.data(), x2.data(), a1, a2);
    multiplyBlockRowSplit<kRodGroups>(K, R, x1.data(), b1);
    multiplyBlockRowSplit<kRodGroups>(K, R, x2.data(), b2);
    DoublePair c1[3], c2[3];  // both vectors in one pass, as the lumped step takes them
    multiplyBlockRowSplitPairs(K, R, x1.data(), x2.data(), c1, c2);
    for (int i = 0; i < 6; ++i) {
      ASSERT_EQ(a1[i], b1[i]) << "block row " << R << ", row " << i;
      ASSERT_EQ(a2[i], b2[i]) << "block row " << R << ", row " << i;
      ASSERT_EQ(a1[i], c1[i / 2][i % 2]) << "block row " << R << ", row " << i;
      ASSERT_EQ(a2[i], c2[i / 2][i % 2]) << "block row " << R << ", row " << i;
    }
    ASSERT_LE((a1 - Kx1.segment<6>(6 * R)).cwiseAbs().maxCoeff(), 1e-12 * (1 + Kx1.cwiseAbs().maxCoeff()));
  }
  SpMat coupled = sim.ops.K;
  coupled.coeffRef(0, 2) += 1.0;  // ux of node 0 to its uz
  coupled.coeffRef(2, 0) += 1.0;
  EXPECT_TRUE(toNodeBlocks(SpMatRow(coupled)).split.empty());
}

// The elastic interfaces' stiffness in node blocks (elasticInterfaceBlocks): split by kInterfaceGroups, far
// fewer distinct blocks than blocks (the geometry repeats from slice to slice), and K_I q within round-off
// and the blocks' tolerance of every interface's elastic force, the law's at openings below delta0 (all elastic,
// contact included: q of both signs) and the sum of the 12 x 12 elastic stiffnesses.
TEST(Kernels, ElasticInterfaceBlocksGiveTheElasticForces) {
  Simulation sim(smallCase("integrator = \"lumped\"\n"));
  const Model& m = sim.model;
  const cohesive::Law& law = sim.materials.law;
  const NodeBlockMatrix KI = elasticInterfaceBlocks(m, law, sim.ops);
  ASSERT_FALSE(KI.split.empty());
  EXPECT_LT(KI.values.size() / 36, KI.valueOf.size() / 2) << "the geometry repeats";
  const int n = m.numDofs();
  const VecX q = 0.02 * law.delta0() * pseudoRandomField(n, 1.0);  // openings well below delta0
  std::vector<double> lambdaMax(m.numInterfaces(), 0.0);
  VecX fLaw;
  ASSERT_EQ(computeForcesForInterfaces(m, law, sim.ops, q, lambdaMax, false, fLaw), 0);
  VecX fSum = VecX::Zero(n);
  for (int i = 0; i < m.numInterfaces(); ++i) {
    const Eigen::Matrix<double, 12, 12> K = cohesive::elasticStiffness(law, m.ifaceGeom[i]);
    const int A = m.ifaceNodes[i][0], B = m.ifaceNodes[i][1];
    Eigen::Matrix<double, 12, 1> u;
    u << q.segment<6>(6 * A), q.segment<6>(6 * B);
    const Eigen::Matrix<double, 12, 1> f = K * u;
    fSum.segment<6>(6 * A) += f.head<6>(), fSum.segment<6>(6 * B) += f.tail<6>();
  }
  const double scale = fLaw.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 0);
  for (int R = 0; R < KI.blockRows; ++R) {
    Vec6 y;
    multiplyBlockRowSplit<kInterfaceGroups>(KI, R, q.data(), y);
    ASSERT_LE((y - fLaw.segment<6>(6 * R)).cwiseAbs().maxCoeff(), 64 * kInterfaceBlockTolerance * scale) << "node " << R;
    ASSERT_LE((y - fSum.segment<6>(6 * R)).cwiseAbs().maxCoeff(), 64 * kInterfaceBlockTolerance * scale) << "node " << R;
  }
}

// The AVX-512 interface rows (multiplyInterfaceRowsAvx512, on CPUs that have it): every entry of K_I q bit for bit
// the multiply-adds of multiplyBlockRowGroups in its order (per row, block by block, column k = 0, 1, 2 of each
// group's 3 x 3 block), each rounded once (std::fma), for every row of the small case's K_I, over an odd number
// of rows (the last row alone).
TEST(Kernels, InterfaceRowsAvx512AreTheFusedRowsBitForBit) {
  if (!cpuHasAvx512()) GTEST_SKIP() << "this CPU has no AVX-512";
  Simulation sim(smallCase("integrator = \"lumped\"\n"));
  const NodeBlockMatrix KI = elasticInterfaceBlocks(sim.model, sim.materials.law, sim.ops);
  ASSERT_FALSE(KI.split.empty());
  const VecX q = pseudoRandomField(sim.model.numDofs(), 1.0);
  const int rows = KI.blockRows - (KI.blockRows % 2 == 0 ? 1 : 0);  // odd
  std::vector<DoublePair> y(3 * static_cast<std::size_t>(rows));
  multiplyInterfaceRowsAvx512(KI, octsOfSplit(KI.split), 0, rows, q.data(), y.data());
  const DofGroups& G = kInterfaceGroups;
  for (int R = 0; R < rows; ++R) {
    double s1[4] = {0, 0, 0, 0}, s2[4] = {0, 0, 0, 0};
    for (int b = KI.start[R]; b < KI.start[R + 1]; ++b) {
      const StoredQuad* B = KI.split.data() + KI.splitRef[b].quad;
      const double* a = q.data() + KI.splitRef[b].dof;
      for (int k = 0; k < 3; ++k)
        for (int l = 0; l < 4; ++l) {
          s1[l] = std::fma(B[k].q[l], a[G.first[k]], s1[l]);
          s2[l] = std::fma(B[3 + k].q[l], a[G.second[k]], s2[l]);
        }
    }
    for (int row = 0; row < 6; ++row) {
      const double expected = G.inFirst(row) ? s1[G.laneOf(row)] : s2[G.laneOf(row)];
      ASSERT_EQ(y[3 * R + row / 2][row % 2], expected) << "row " << R << ", DOF " << row;
    }
  }
}

// |a| of a pair clears the sign bits: -0 gives +0, and the magnitudes are exact.
TEST(Kernels, MagnitudeOfAPairClearsTheSigns) {
  const DoublePair m = magnitude(DoublePair{-1.5, 2.25});
  EXPECT_EQ(m[0], 1.5);
  EXPECT_EQ(m[1], 2.25);
  const DoublePair zero = magnitude(DoublePair{-0.0, 0.0});
  EXPECT_FALSE(std::signbit(zero[0]));
  EXPECT_FALSE(std::signbit(zero[1]));
}

// Blocks that agree to the tolerance share one stored block; blocks that differ by more, or only bit for bit
// at tolerance 0, do not.
TEST(Kernels, NodeBlocksShareBlocksThatAgreeToTheTolerance) {
  std::array<double, 36> a{}, b{}, c{};
  for (int e = 0; e < 36; ++e) a[e] = 1.0 + e, b[e] = a[e] * (1 + 1e-14), c[e] = a[e] * (1 + 1e-9);
  const std::vector<std::array<double, 36>> rows = {a, b, c};
  auto build = [&](double tolerance) {
    return toNodeBlocks(3, [&](int R, BlockRow& row) { row.push_back({R, rows[R]}); }, kRodGroups, tolerance);
  };
  const NodeBlockMatrix tolerant = build(kInterfaceBlockTolerance), exact = build(0);
  EXPECT_EQ(tolerant.values.size(), 2u * 36);
  EXPECT_EQ(tolerant.valueOf, (std::vector<int>{0, 0, 1}));
  EXPECT_EQ(exact.values.size(), 3u * 36);
  EXPECT_TRUE(tolerant.split.empty()) << "these blocks couple the groups";
}

// The lumped step's position update (in its node pass, two DOFs at a time, the maxima in pairs): q_{n+1} of every
// free DOF is q_n + dt v_{n+1/2} (with FMA, where the node rows' copy for this CPU has it, rounded once: either way
// the one-DOF-at-a-time loop's value bit for bit), the grips' q is shape U(t_{n+1}), and the move bound the
// schedules rely on (lastStepMoveBound) holds every DOF's move and is the documented sum of the exact maxima
// max |dt v|, max |q|; the same q, v at 1 and 2 threads.
TEST(Kernels, LumpedStepMovesPositionsByDtTimesTheHalfStepVelocity) {
  const int before = omp_get_max_threads();
  std::vector<VecX> qAt, vAt;  // per thread count: q and v_{n+1/2} after the steps
  for (int threads : {1, 2}) {
    Simulation sim(smallCase("integrator = \"lumped\"\n"));
    omp_set_num_threads(threads);
    State& s = sim.state;
    const double delta0 = sim.materials.law.delta0(), dt = sim.integrator->timeStep();
    s.q = pseudoRandomField(sim.model.numDofs(), 0.3 * delta0);  // elastic: no interface past delta0
    s.v = pseudoRandomField(sim.model.numDofs(), 1e-3).reverse();
    sim.integrator->initialise(sim.model, sim.materials, sim.ops, s);
    double largestShape = 0;
    for (double shape : sim.ops.prescribedShape) largestShape = std::max(largestShape, std::abs(shape));
    for (int n = 0; n < 5; ++n) {
      const VecX q0 = s.q;
      const double U0 = s.appliedDisplacement;
      sim.step();
      const VecX& v = s.vHalf;  // v_{n+1/2}
      double largestStep = 0, largestValue = 0, moved = 0;
      for (int i = 0; i < sim.model.numDofs(); ++i) {
        const double step = dt * v[i], twice = q0[i] + step, once = std::fma(dt, v[i], q0[i]);
        largestStep = std::max(largestStep, std::abs(step));
        moved = std::max(moved, std::abs(s.q[i] - q0[i]));
        if (sim.ops.dofToFree[i] >= 0) {
          ASSERT_TRUE(s.q[i] == twice || s.q[i] == once) << "step " << n << ", DOF " << i;
          largestValue = std::max(largestValue, std::abs(s.q[i]));
        } else {
          largestValue = std::max(largestValue, std::abs(twice));  // the node pass's q, before the grips' own
        }
      }
      for (std::size_t g = 0; g < sim.ops.prescribedDofs.size(); ++g)
        ASSERT_EQ(s.q[sim.ops.prescribedDofs[g]], sim.ops.prescribedShape[g] * s.appliedDisplacement);
      const double U1 = s.appliedDisplacement;
      const double largest = std::max({largestValue, largestShape * std::abs(U1), largestShape * std::abs(U0)});
      const double bound = std::max(largestStep, largestShape * std::abs(U1 - U0)) * (1.0 + 1e-12) + std::ldexp(largest, -52);
      EXPECT_GE(sim.integrator->lastStepMoveBound(), moved) << "step " << n;
      EXPECT_EQ(sim.integrator->lastStepMoveBound(), bound) << "step " << n;
      // per slice: each holds its own DOFs' moves, and the largest is the global bound
      const std::vector<double>& ofSlices = sim.integrator->lastStepMoveBoundsOfSlices();
      ASSERT_EQ(static_cast<int>(ofSlices.size()), sim.model.numSlices);
      const std::vector<double> exact = movesOfSlices(sim.model, s.q - q0);
      for (int k = 0; k < sim.model.numSlices; ++k) EXPECT_GE(ofSlices[k] * (1 + 1e-12) + 1e-300, exact[k]) << "slice " << k;
      EXPECT_EQ(*std::max_element(ofSlices.begin(), ofSlices.end()), bound) << "step " << n;
    }
    qAt.push_back(s.q);
    vAt.push_back(s.vHalf);
  }
  omp_set_num_threads(before);
  EXPECT_EQ(qAt[0], qAt[1]);
  EXPECT_EQ(vAt[0], vAt[1]);
}

TEST(Kernels, FailedFactorisationIsARunFailure) {
  Simulation sim(smallCase("integrator = \"paper\"\n"));
  sim.ops.M = -sim.ops.M;
  sim.ops.K = -sim.ops.K;
  try {
    sim.integrator->updateOperators(sim.ops);
    FAIL() << "factorising a negative definite H should fail";
  } catch (const SolverError& e) {
    EXPECT_EQ(exitCodeOf(e), exit_code::run_failed) << e.what();
  }
}

// A time step above the stable limit is bad input: IntegratorError, exit status out_of_range (7).
TEST(Kernels, RefusedTimeStepIsOutOfRange) {
  try {
    Simulation sim(smallCase("integrator = \"paper\"\ndt_factor = 0.5\n"));
    FAIL() << "dt_factor 0.5 should be refused";
  } catch (const IntegratorError& e) {
    EXPECT_EQ(exitCodeOf(e), exit_code::out_of_range) << e.what();
  }
}

// Loading::timeOfDisplacement inverts Loading::displacement inside the ramp (bisection), after it (closed
// form), and without a ramp.
TEST(Kernels, TimeOfDisplacementInvertsTheLoading) {
  for (double rampTime : {0.0, 40.0}) {
    const Loading loading{0.003, rampTime};
    for (double t : {0.0, 1e-3, 0.7, 13.0, 39.9, 40.0, 41.0, 500.0}) {
      const double U = loading.displacement(t);
      EXPECT_NEAR(loading.displacement(loading.timeOfDisplacement(U)), U, 1e-13 * std::max(U, 1e-3))
          << "ramp " << rampTime << " t " << t;
      if (t > 1.0) EXPECT_NEAR(loading.timeOfDisplacement(U), t, 1e-9 * t) << "ramp " << rampTime;
    }
  }
}

// The static elastic start: the state is static equilibrium at U* = fraction U_c (free DOFs carry no net
// force), its most loaded interface or rod element sits at exactly `fraction` of its limit, nothing is
// inelastic, the time is where the loading reaches U*, and the external work is what the specimen holds.
// The third model is larger (24 x 24 d). With the pre-crack tip at a quarter point (docs/model.md, Geometry) it
// holds no mechanism, and says so (a tip at a0 = 40 h_e would put a crisscross on slice 40 and a rod's crossing
// exactly on slice 0, and round-off would cut a rod end off onto a single interface: a mechanism).
TEST(Kernels, StaticStartIsEquilibriumAtAFractionOfFirstDamage) {
  for (const char* integrator : {"lumped", "paper", "lumped24"}) {
    const bool large = std::string(integrator) == "lumped24";
    Simulation sim(large ? parseCase("theta_D = 30\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\n"
                                     "E_transverse_over_Er = 0.1\nintegrator = \"lumped\"\n",
                                     "kernels", "", {"w_s_over_d=24", "h_s_over_d=24"})
                         : smallCase(std::string("integrator = \"") + integrator + "\"\n"));
    const double fraction = 0.9;
    const StaticStart st = sim.startFromStaticElastic(fraction);
    const State& s = sim.state;
    ASSERT_TRUE(std::isfinite(st.firstDamageDisplacement) && st.firstDamageDisplacement > 0);
    EXPECT_FALSE(st.mechanism) << integrator;
    EXPECT_DOUBLE_EQ(st.displacement, fraction * st.firstDamageDisplacement);
    EXPECT_NEAR(s.appliedDisplacement, st.displacement, 1e-12 * st.displacement);
    EXPECT_NEAR(sim.materials.loading.displacement(s.time), st.displacement, 1e-12 * st.displacement);
    EXPECT_EQ(s.step, 0);
    // the limit that sets U_c is reached at exactly `fraction` of it
    double worstLambda = 0;  // the largest effective separation (lambdaMax records none below delta0)
    for (int i = 0; i < sim.model.numInterfaces(); ++i)
      worstLambda = std::max(worstLambda, cohesive::effectiveSeparation(computeLocalOpening(sim.model, s.q, i)));
    std::vector<double> ratio;
    computeStressRatiosForBeams(sim.model, sim.materials, s.q, s.beamBroken, ratio);
    const double worstRod = *std::max_element(ratio.begin(), ratio.end());
    const double used = st.limitedByRod ? worstRod : worstLambda / sim.materials.law.delta0();
    EXPECT_NEAR(used, fraction, 1e-9) << integrator;
    EXPECT_LT(worstRod, 1.0);
    EXPECT_EQ(sim.countInelasticInterfaces(), 0);
    // static equilibrium: K q + f_iface = 0 on the free DOFs (to the solve's round-off)
    std::vector<double> lambda = s.lambdaMax;
    VecX fI;
    computeForcesForInterfaces(sim.model, sim.materials.law, sim.ops, s.q, lambda, false, fI);
    const VecX residual = sim.ops.K * s.q + fI;
    double worstFree = 0;
    for (int dof : sim.ops.freeDofs) worstFree = std::max(worstFree, std::abs(residual[dof]));
    EXPECT_LT(worstFree, 1e-8 * s.reaction.cwiseAbs().maxCoeff()) << integrator;
    // the grips' work is the energy held: balance error 0 in the first history row
    const Measurement r = sim.measure();
    EXPECT_NEAR(r.balanceError, 0.0, 1e-12) << integrator;
    EXPECT_GT(r.strainBeams + r.strainInterfaces, 0.0);
    // every DOF moves with the loading (v = U' q1): nothing moves beyond it (to round-off); the loading's own motion is slow
    // against the small models' stiffness (the 24 x 24 d one, at the default rate, moves its slowest modes)
    EXPECT_LT(r.kineticBeyond, 1e-6 * r.kinetic) << integrator << " " << r.kinetic;
    if (!large) EXPECT_LT(r.kinetic, 1e-3 * (r.strainBeams + r.strainInterfaces)) << integrator;
  }
}

// A stiffness with a mechanism (a free pair of DOFs joined only to each other, and a DOF joined to nothing):
// the solve still gives the exact static field of the rest, keeps the mechanism where it is, and says so.
TEST(Kernels, StaticSolveKeepsAMechanismInPlace) {
  // springs 0-1 (k = 2) and 1-2 (k = 1): u0 = 0, u2 = 3 prescribed, so u1 = 1; DOFs 3-4 a free pair (k = 5), 5 free
  std::vector<Eigen::Triplet<double>> t;
  auto spring = [&](int a, int b, double k) {
    t.emplace_back(a, a, k), t.emplace_back(b, b, k), t.emplace_back(a, b, -k), t.emplace_back(b, a, -k);
  };
  spring(0, 1, 2.0);
  spring(1, 2, 1.0);
  spring(3, 4, 5.0);
  t.emplace_back(5, 5, 0.0);
  SpMat K(6, 6);
  K.setFromTriplets(t.begin(), t.end());
  bool mechanism = false;
  const VecX u = solveStaticPrescribed(K, {0, 2}, {0.0, 3.0}, &mechanism);
  EXPECT_TRUE(mechanism);
  EXPECT_NEAR(u[1], 1.0, 1e-12);
  EXPECT_EQ(u[0], 0.0);
  EXPECT_EQ(u[2], 3.0);
  for (int i = 3; i < 6; ++i) EXPECT_NEAR(u[i], 0.0, 1e-12) << i;
  // without the mechanism the flag stays down
  SpMat K2 = K.topLeftCorner(3, 3);
  const VecX u2 = solveStaticPrescribed(K2, {0, 2}, {0.0, 3.0}, &mechanism);
  EXPECT_FALSE(mechanism);
  EXPECT_NEAR(u2[1], 1.0, 1e-12);
}

// Nothing to start before: with unbreakable interfaces and rods U_c is infinite; refused as bad input (7).
// The static solves run the BLAS at one thread whatever its count (solveStaticPrescribed), and give its count back:
// the transverse modulus (a static solve on a block of the case) is the same, bit for bit, with the BLAS at one
// thread or two. On the CPUs where OpenBLAS's threaded kernels add in another order this is what keeps a run's
// numbers independent of the thread count (tests/python/test_threads.py checks whole runs).
TEST(Kernels, StaticSolveDoesNotDependOnTheBlasThreadCount) {
  const int before = blasThreadCount();
  if (before == 0) GTEST_SKIP() << "the BLAS linked here has no thread count";
  // the block measureTransverseModulus uses at its largest, 24 x 12 d: OpenBLAS threads only large enough products
  const CaseParams p = parseCase("theta_D = 30\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\n"
                                 "w_s_over_d = 24\nh_s_over_d = 12\n", "kernels", "", {});
  std::vector<double> modulus;
  for (int threads : {1, 2}) {
    setBlasThreadCount(threads);
    modulus.push_back(measureTransverseModulus(p));
    EXPECT_EQ(blasThreadCount(), threads) << "the solve gives the BLAS its count back";
  }
  setBlasThreadCount(before);
  EXPECT_EQ(modulus[0], modulus[1]);
}

TEST(Kernels, StaticStartWithoutDamageIsRefused) {
  Simulation sim(smallCase("integrator = \"lumped\"\ninterfaces_breakable = false\nrods_breakable = false\n"));
  try {
    sim.startFromStaticElastic(0.5);
    FAIL() << "static start without any damage limit should be refused";
  } catch (const IntegratorError& e) {
    EXPECT_EQ(exitCodeOf(e), exit_code::out_of_range) << e.what();
    EXPECT_NE(std::string(e.what()).find("static_start"), std::string::npos) << e.what();
  }
}
