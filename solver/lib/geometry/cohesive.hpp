#pragma once
// The rigid-arm interface element, as pure functions: its kinematics (the opening of two nodes' rigid arms from
// their displacements and rotations), its forces and moments from the cohesive law (laws/cohesive_law.hpp) and
// its elastic stiffness. docs/model.md. Normalised units (d = 1, E_r = 1, rho_r = 1).
#include <Eigen/Dense>

#include "laws/cohesive_law.hpp"

namespace enamel::cohesive {

using Mat3 = Eigen::Matrix3d;

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
