#include "geometry/cohesive.hpp"

#include <stdexcept>

namespace enamel::cohesive {

Mat3 makeFrame(const Vec3& normal) {
  const Vec3 n = normal.normalized();
  Vec3 t1 = Vec3::UnitX() - n.x() * n;  // e_x minus its normal part
  if (t1.norm() < 1e-8) t1 = Vec3::UnitY() - n.y() * n;
  t1.normalize();
  Mat3 frame;
  frame.row(0) = n.transpose();
  frame.row(1) = t1.transpose();
  frame.row(2) = n.cross(t1).transpose();
  return frame;
}

// delta = (uB + thB x rB) - (uA + thA x rA)
Vec3 computeOpening(const InterfaceGeometry& g, const Vec3& uA, const Vec3& thA, const Vec3& uB, const Vec3& thB) {
  return (uB + thB.cross(g.armB)) - (uA + thA.cross(g.armA));
}

// t = traction(R delta), F_B = -A R^T t
Vec3 computeInterfaceForceOnB(const Law& law, const InterfaceGeometry& g, const Vec3& uA, const Vec3& thA,
                              const Vec3& uB, const Vec3& thB, double& lambdaMax) {
  const Vec3 openingLocal = g.frame * computeOpening(g, uA, thA, uB, thB);
  const Vec3 tLocal = computeTraction(law, openingLocal, lambdaMax);
  const Vec3 tGlobal = g.frame.transpose() * tLocal;  // evaluated first: Eigen would fold -area into the product
  return -g.area * tGlobal;
}

// B: (F_B, rB x F_B);  A: F_A = -F_B, (F_A, rA x F_A)
Wrench wrenchOnSide(const InterfaceGeometry& g, const Vec3& forceOnB, bool sideB) {
  if (sideB) return Wrench{forceOnB, g.armB.cross(forceOnB)};
  const Vec3 forceA = -forceOnB;
  return Wrench{forceA, g.armA.cross(forceA)};
}

SliceInterface packInSlice(const InterfaceGeometry& g) {
  const Vec3 n = g.frame.row(0).transpose();
  if (n.x() != 0.0 || g.armA.x() != 0.0 || g.armB.x() != 0.0 ||
      g.frame.row(1).transpose() != Vec3::UnitX() || g.frame.row(2).transpose() != n.cross(Vec3::UnitX()))
    throw std::invalid_argument("interface geometry is not in one yz-slice (normal or arm with an x part)");
  return SliceInterface{n.y(), n.z(), g.armA.y(), g.armA.z(), g.armB.y(), g.armB.z(), g.area};
}

// delta = (uB + thB x rB) - (uA + thA x rA) with r = (0, ry, rz): thB x rB = (thy rz - thz ry, -thx rz, thx ry)
// (the products the general form multiplies by the arms' zero x left out).
Vec3 computeOpening(const SliceInterface& g, const Vec3& uA, const Vec3& thA, const Vec3& uB, const Vec3& thB) {
  const double ox = (uB.x() + (thB.y() * g.armBz - thB.z() * g.armBy)) - (uA.x() + (thA.y() * g.armAz - thA.z() * g.armAy));
  const double oy = (uB.y() + (-(thB.x() * g.armBz))) - (uA.y() + (-(thA.x() * g.armAz)));
  const double oz = (uB.z() + thB.x() * g.armBy) - (uA.z() + thA.x() * g.armAy);
  return Vec3(ox, oy, oz);
}

// local opening (n . delta, delta_x, t2 . delta) with t2 = (0, nz, -ny)
Vec3 localOpening(const SliceInterface& g, const Vec3& opening) {
  return Vec3(g.ny * opening.y() + g.nz * opening.z(), opening.x(), g.nz * opening.y() + (-g.ny) * opening.z());
}

// F_B = -A (n t_n + e_x t_1 + t2 t_2)
Vec3 forceOnBOfTraction(const SliceInterface& g, const Vec3& t) {
  return -g.area * Vec3(t(1), g.ny * t(0) + g.nz * t(2), g.nz * t(0) + (-g.ny) * t(2));
}

// The opening, its local form, the traction and the force as above. Every product the general form multiplies
// by an exact zero is left out: the sums keep their order, so the result is the general form's bit for bit (a
// zero product adds nothing exactly, without FMA contraction).
Vec3 computeInterfaceForceOnB(const Law& law, const SliceInterface& g, const Vec3& uA, const Vec3& thA,
                              const Vec3& uB, const Vec3& thB, double& lambdaMax) {
  const Vec3 t = computeTraction(law, localOpening(g, computeOpening(g, uA, thA, uB, thB)), lambdaMax);
  return forceOnBOfTraction(g, t);
}

// t = k R delta in every direction while S = k (tension, shear and contact alike), so F_B = -A R^T k R delta
// = -k A delta (R orthonormal).
Vec3 elasticForceOnB(const Law& law, const SliceInterface& g, const Vec3& uA, const Vec3& thA, const Vec3& uB,
                     const Vec3& thB) {
  return -(law.k * g.area) * computeOpening(g, uA, thA, uB, thB);
}

// B: (F_B, rB x F_B);  A: F_A = -F_B, (F_A, rA x F_A)
// r x F with r = (0, ry, rz) written out: (ry Fz - rz Fy, rz Fx, -ry Fx), the general cross product less its
// products by the zero x of the arm (equal to it, up to the sign of a zero).
Wrench wrenchOnSide(const SliceInterface& g, const Vec3& forceOnB, bool sideB) {
  const double ry = sideB ? g.armBy : g.armAy, rz = sideB ? g.armBz : g.armAz;
  const double fx = sideB ? forceOnB.x() : -forceOnB.x(), fy = sideB ? forceOnB.y() : -forceOnB.y(),
               fz = sideB ? forceOnB.z() : -forceOnB.z();
  return Wrench{Vec3(fx, fy, fz), Vec3(ry * fz - rz * fy, rz * fx, -(ry * fx))};
}

// F_B as above, then the wrench on each side
NodalWrench computeInterfaceForces(const Law& law, const InterfaceGeometry& g, const Vec3& uA, const Vec3& thA,
                                   const Vec3& uB, const Vec3& thB, double& lambdaMax) {
  const Vec3 forceB = computeInterfaceForceOnB(law, g, uA, thA, uB, thB, lambdaMax);
  const Wrench onA = wrenchOnSide(g, forceB, false), onB = wrenchOnSide(g, forceB, true);
  return NodalWrench{onA.force, onA.moment, onB.force, onB.moment};
}

// delta = Bq with B = [-I, [rA]x, I, -[rB]x] (theta x r = -[r]x theta), q = (uA, thA, uB, thB);
// undamaged traction is k delta in every direction (tension: S = k; compression: contact k dn), so
// f = -A B^T R^T (k R delta) = -k A B^T B q  =>  K = k A B^T B.
Eigen::Matrix<double, 12, 12> elasticStiffness(const Law& law, const InterfaceGeometry& g) {
  auto skew = [](const Vec3& r) {
    Mat3 s;
    s << 0.0, -r.z(), r.y(), r.z(), 0.0, -r.x(), -r.y(), r.x(), 0.0;
    return s;
  };
  Eigen::Matrix<double, 3, 12> B;
  B << -Mat3::Identity(), skew(g.armA), Mat3::Identity(), -skew(g.armB);
  return law.k * g.area * (B.transpose() * B);
}

}  // namespace enamel::cohesive
