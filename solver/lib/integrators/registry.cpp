// The schemes of this build by name: the one table makeIntegrator looks in (a scheme is one row here and its
// name among the `integrator` key's choices, case_params.hpp; tests/cpp/test_integrators.cpp checks both agree).
#include <string>
#include <vector>

#include "integrators.hpp"
#include "schemes.hpp"

namespace enamel {

const std::vector<IntegratorEntry>& integratorRegistry() {
  static const std::vector<IntegratorEntry> table = {
      {"paper", makePaperIntegrator},
      {"lumped", makeLumpedIntegrator},
  };
  return table;
}

std::unique_ptr<Integrator> makeIntegrator(const CaseParams& p, const Model& m, const Materials& mat,
                                           const Operators& ops) {
  std::string available;
  for (const IntegratorEntry& e : integratorRegistry()) {
    if (p.integrator == e.name) return e.make(p, m, mat, ops);
    available += (available.empty() ? "" : ", ") + std::string(e.name);
  }
  throw IntegratorError("integrator '" + p.integrator + "' is not available in this build (available: " + available +
                        ")");
}

}  // namespace enamel
