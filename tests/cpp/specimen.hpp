#pragma once
// The tests' common specimen: w x h d at theta_D, pre-cracked to the middle, slices h_e = 0.3 d.
#include "geometry/geometry.hpp"

inline enamel::GeometryParams specimen(double thetaDeg, double w, double h) {
  enamel::GeometryParams p;
  p.theta_deg = thetaDeg;
  p.w_s = w;
  p.h_s = h;
  p.a0 = 0.5 * w;
  p.h_e = 0.3;
  return p;
}
