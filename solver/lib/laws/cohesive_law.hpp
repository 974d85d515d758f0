#pragma once
// The interface cohesive law (symmetric trapezoid) as pure functions of a local opening (n, t1, t2) and its
// history; the interface element that applies it is geometry/cohesive.hpp. docs/model.md. Normalised units
// (d = 1, E_r = 1, rho_r = 1).
#include <Eigen/Dense>

namespace enamel::cohesive {

using Vec3 = Eigen::Vector3d;

// Trapezoid set by (k, sigma0, Gamma) and its softening length: elastic to delta0 = sigma0/k, plateau to
// delta1, linear to zero at deltaf = delta1 + L, L = softeningOverDelta0 * delta0 (case key
// softening_over_delta0). Area = Gamma:
//   Gamma = sigma0 delta0/2 + sigma0 (delta1 - delta0) + sigma0 L/2  =>  delta1 = Gamma/sigma0 + (delta0 - L)/2.
// Default L = delta0 (the symmetric trapezoid of docs/model.md): delta1 = Gamma/sigma0, deltaf = delta1 + delta0,
// and the same floating-point numbers as before the key (delta0 - 1.0*delta0 = 0 exactly). Requires
// delta1 >= delta0, i.e. L/delta0 <= 2 G - 1 with G = Gamma k/sigma0^2 (equality: the triangle, no plateau).
//
// Mixed mode (case key shear_strength_ratio = beta): the law acts on the effective separation
//   lambda = sqrt(<dn>_+^2 + (dt1^2 + dt2^2)/beta^2),
// and the traction is S(lambdaMax) (<dn>_+, dt1, dt2) (+ contact), so the elastic stiffness is k in every mode,
// the shear strength beta sigma0 and the shear fracture energy beta^2 Gamma. beta = 1 (the default) is the law
// before the key, bit for bit: shearWeight = 1/beta^2 is then 1 exactly and every product by it exact.
struct Law {
  double k, sigma0, Gamma;
  double softeningOverDelta0 = 1.0;  // L/delta0 = (deltaf - delta1)/delta0
  double shearStrengthRatio = 1.0;   // beta: shear strength / sigma0
  double shearWeight = 1.0;          // 1/beta^2, the weight of dt1^2 + dt2^2 in lambda^2 (makeLaw sets it)
  bool isotropic() const { return shearWeight == 1.0; }  // beta = 1: one law in every mode
  double delta0() const;
  double softeningLength() const;  // L = softeningOverDelta0 * delta0
  double delta1() const;
  double deltaf() const;
};

// throws std::invalid_argument (message names the quantity) if k, sigma0, Gamma not > 0, Gamma < sigma0^2/k,
// softeningOverDelta0 outside (0, 2 G - 1] (G = Gamma k/sigma0^2; 1e-12 relative slack for round-off in G), or
// shearStrengthRatio not in (0, 10] (the range of the case key).
inline constexpr double kMaxShearStrengthRatio = 10.0;
Law makeLaw(double k, double sigma0, double Gamma, double softeningOverDelta0 = 1.0, double shearStrengthRatio = 1.0);

// Monotonic envelope T(lambda) of the effective traction for effective separation lambda >= 0.
double envelopeTraction(const Law& law, double lambda);

// Effective separation lambda = sqrt(<dn>_+^2 + dt1^2 + dt2^2) of a local opening (dn, dt1, dt2): the law's
// at beta = 1.
double effectiveSeparation(const Vec3& openingLocal);
// The law's effective separation lambda = sqrt(<dn>_+^2 + (dt1^2 + dt2^2)/beta^2); the one above at beta = 1,
// bit for bit.
double effectiveSeparation(const Law& law, const Vec3& openingLocal);

// |(<dn>_+, dt1, dt2)|^2 / lambda^2: what the work of the law along a radial opening is, per unit of the
// normal-mode work (1 in pure normal opening, beta^2 in pure shear, 1 for every opening at beta = 1; 1 at a
// zero opening).
double modeFactor(const Law& law, const Vec3& openingLocal);

// Secant stiffness S(lambdaMax) = envelope(lambdaMax)/lambdaMax; k while lambdaMax <= delta0, 0 once failed.
double secantStiffness(const Law& law, double lambdaMax);

// Traction (local n, t1, t2 components, tension positive) for a local opening, updating the history
// variable lambdaMax (largest lambda reached; irreversible). Same law in every mode on lambda; secant
// (damage) unloading: T = envelope(lambdaMax) * lambda / lambdaMax when lambda < lambdaMax (elastic k*lambda
// while lambdaMax <= delta0); traction vector = S(lambdaMax) * (<dn>_+, dt1, dt2) (= T/lambda * (...) at
// beta = 1), lambda of effectiveSeparation(law, .); plus penalty contact
// k * min(dn, 0) on the normal component, always, even after failure. Failed (lambdaMax >= deltaf): zero
// except contact. lambdaMax records lambda only once lambda^2 passes kElasticTrack delta0^2 (the elastic
// track, where the law does not depend on it: cohesive_law.cpp); to know lambda itself use effectiveSeparation.
inline constexpr double kElasticTrack = 1.0 - 1e-6;
Vec3 computeTraction(const Law& law, const Vec3& openingLocal, double& lambdaMax);

// Energy per unit area stored (recoverable) at this state: 0.5*S*|(<dn>_+, dt1, dt2)|^2 + 0.5*k*<-dn>_+^2
// (= 0.5*S*lambda^2 + ... at beta = 1), S = secant stiffness. S is evaluated at max(lambdaMax, lambda), i.e. at
// the history computeTraction would produce for this opening.
double storedEnergyDensity(const Law& law, const Vec3& openingLocal, double lambdaMax);

// Energy per unit area dissipated once lambdaMax has been reached, along a path of mode factor 1 (at beta = 1:
// along any path): area under the envelope up to lambdaMax minus the recoverable triangle
// 0.5*envelope(lambdaMax)*lambdaMax (0 while elastic, Gamma when failed).
double dissipatedEnergyDensity(const Law& law, double lambdaMax);

// The energy per unit area dissipated while lambdaMax grows from lambdaMaxBefore to lambdaMaxAfter at the
// local opening `openingLocal` (at which lambda = lambdaMaxAfter, or any multiple of it):
//   modeFactor(opening) * (dissipatedEnergyDensity(after) - dissipatedEnergyDensity(before)).
// The dissipation rate of the secant law is -1/2 S'(lambdaMax) |(<dn>_+, dt1, dt2)|^2 dlambdaMax, and on the
// loading surface |(<dn>_+, dt1, dt2)|^2 = modeFactor lambda^2, so summing this over the steps of a path gives
// its dissipation (exact for a path of fixed mode; beta^2 Gamma to failure in pure shear).
double dissipationIncrement(const Law& law, const Vec3& openingLocal, double lambdaMaxBefore, double lambdaMaxAfter);

double damage(const Law& law, double lambdaMax);     // 1 - S/k, in [0,1]
bool isInelastic(const Law& law, double lambdaMax);  // lambdaMax > delta0
bool isFailed(const Law& law, double lambdaMax);     // lambdaMax >= deltaf

}  // namespace enamel::cohesive
