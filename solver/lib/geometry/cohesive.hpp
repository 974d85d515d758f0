#pragma once
// Interface cohesive law (symmetric trapezoid) and the rigid-arm interface element, as pure functions.
// docs/model.md. Normalised units (d = 1, E_r = 1, rho_r = 1).
#include <Eigen/Dense>

namespace enamel::cohesive {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;

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
// track, where the law does not depend on it: cohesive.cpp); to know lambda itself use effectiveSeparation.
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

// Interface element between node A and node B (rod centres in one slice; B may be a periodic image).
// Massless; forces applied directly as equal and opposite nodal forces (never assembled into K).
struct InterfaceGeometry {
  Mat3 frame;   // rows: n (unit, from A towards B), t1, t2 (right-handed orthonormal)
  Vec3 armA;    // midpoint of the shared Voronoi edge minus position of A
  Vec3 armB;    // same midpoint minus position of B (B's image position for a periodic pair)
  double area;  // A_i = h_e * l_i
};

// Right-handed orthonormal frame with rows (n, t1, t2) for a normal direction (need not be unit length):
// t1 = the part of e_x orthogonal to n (the rod axis direction for an in-slice normal; e_y if n is along x),
// t2 = n x t1.
Mat3 makeFrame(const Vec3& normal);

// Rigid-arm kinematics: opening (global frame) = (uB + thB x armB) - (uA + thA x armA).
Vec3 computeOpening(const InterfaceGeometry& g, const Vec3& uA, const Vec3& thA, const Vec3& uB, const Vec3& thB);

struct NodalWrench { Vec3 forceA, momentA, forceB, momentB; };  // forces/moments exerted ON the nodes
struct Wrench { Vec3 force, moment; };

// Force on B = -area * frame^T * t_local; force on A = minus that; moments = arm x force
// (computeInterfaceForceOnB, then wrenchOnSide for each side: what the solver's gather calls).
NodalWrench computeInterfaceForces(const Law& law, const InterfaceGeometry& g, const Vec3& uA, const Vec3& thA,
                                   const Vec3& uB, const Vec3& thB, double& lambdaMax);

// The force on B alone: all an interface needs to store, since F_A = -F_B and the moments are arm x force.
Vec3 computeInterfaceForceOnB(const Law& law, const InterfaceGeometry& g, const Vec3& uA, const Vec3& thA,
                              const Vec3& uB, const Vec3& thB, double& lambdaMax);

// The wrench on one node from the force on B: on B (F_B, r_B x F_B), on A (F_A = -F_B, r_A x F_A).
Wrench wrenchOnSide(const InterfaceGeometry& g, const Vec3& forceOnB, bool sideB);

// The same interface in the compact form the force kernel reads (56 bytes instead of 128): both nodes lie in
// one yz-slice, so the normal has no x part, the frame follows from it (n = (0, ny, nz), t1 = e_x,
// t2 = n x e_x = (0, nz, -ny)) and both arms lie in the slice (no x part).
struct SliceInterface {
  double ny, nz;          // unit normal n = (0, ny, nz), from A towards B
  double armAy, armAz;    // armA = (0, armAy, armAz)
  double armBy, armBz;    // armB = (0, armBy, armBz)
  double area;
};

// The compact form of an in-slice interface; throws std::invalid_argument when g is not one (a normal or an
// arm with an x part, or a frame other than makeFrame's for that normal).
SliceInterface packInSlice(const InterfaceGeometry& g);

// The compact form's pieces: the opening in the global frame (computeOpening), its local components (n, t1,
// t2) (frame * opening), and the force on B of a local traction t (-area frame^T t).
Vec3 computeOpening(const SliceInterface& g, const Vec3& uA, const Vec3& thA, const Vec3& uB, const Vec3& thB);
Vec3 localOpening(const SliceInterface& g, const Vec3& opening);
Vec3 forceOnBOfTraction(const SliceInterface& g, const Vec3& t);

// computeInterfaceForceOnB for the compact form (the code the solver runs): the same opening, traction and
// force, written out for the known zeros of the frame and the arms; equal to the general form bit for bit.
Vec3 computeInterfaceForceOnB(const Law& law, const SliceInterface& g, const Vec3& uA, const Vec3& thA,
                              const Vec3& uB, const Vec3& thB, double& lambdaMax);

// The force on B while the interface is on the elastic branch (secantStiffness(law, lambdaMax) = k): the
// traction is k times the local opening in every direction, contact included, so F_B = -k area opening, linear
// in the DOFs; computeInterfaceForceOnB's value there up to round-off (the frame's rotations left out).
Vec3 elasticForceOnB(const Law& law, const SliceInterface& g, const Vec3& uA, const Vec3& thA, const Vec3& uB,
                     const Vec3& thB);

// wrenchOnSide for the compact form.
Wrench wrenchOnSide(const SliceInterface& g, const Vec3& forceOnB, bool sideB);

// Linearised (undamaged, elastic) interface stiffness 12x12 in the DOF order (uA, thA, uB, thB), k*area with
// the rigid arms; used only to estimate frequencies / transverse modulus, never in the time loop.
Eigen::Matrix<double, 12, 12> elasticStiffness(const Law& law, const InterfaceGeometry& g);

}  // namespace enamel::cohesive
