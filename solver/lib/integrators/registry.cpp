// The schemes of this build: the one table makeIntegrator looks in (a scheme is one row here and one enumerator
// of IntegratorScheme, choices.hpp, whose name is the `integrator` key's value; tests/cpp/test_integrators.cpp
// checks that every enumerator has its row, in order).
#include <string>
#include <vector>

#include "integrators/integrators.hpp"
#include "integrators/schemes.hpp"

namespace enamel {

const std::vector<IntegratorEntry>& integratorRegistry() {
  static const std::vector<IntegratorEntry> table = {
      {IntegratorScheme::paper, makePaperIntegrator, paperCosts},
      {IntegratorScheme::lumped, makeLumpedIntegrator, lumpedCosts},
  };
  return table;
}

const IntegratorEntry& integratorEntry(IntegratorScheme scheme) {
  std::string available;
  for (const IntegratorEntry& e : integratorRegistry()) {
    if (scheme == e.scheme) return e;
    available += (available.empty() ? "" : ", ") + nameOf(e.scheme);
  }
  throw IntegratorError("integrator '" + nameOf(scheme) + "' is not available in this build (available: " +
                        available + ")");
}

std::unique_ptr<Integrator> makeIntegrator(const CaseParams& p, const Model& m, const Materials& mat,
                                           const Operators& ops) {
  return integratorEntry(p.integrator).make(p, m, mat, ops);
}

}  // namespace enamel
