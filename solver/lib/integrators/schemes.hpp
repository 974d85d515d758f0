#pragma once
// The factory and the cost estimate of each scheme, one scheme per file of solver/lib/integrators/ (registry.cpp
// lists them by name).
#include <memory>

#include "integrators/integrators.hpp"

namespace enamel {

/// `paper` (newmark.cpp): Newmark beta = 0, consistent mass, H = M + dt/2 C factorised.
std::unique_ptr<Integrator> makePaperIntegrator(const CaseParams& p, const Model& m, const Materials& mat,
                                                const Operators& ops);
/// `paper`'s costs (newmark.cpp): its factor's fill and solve grow with the nodes of a slice.
SchemeCosts paperCosts(const CaseParams& p, const SchemeSizes& sizes);
/// `lumped` (lumped.cpp): central differences with a diagonal mass.
std::unique_ptr<Integrator> makeLumpedIntegrator(const CaseParams& p, const Model& m, const Materials& mat,
                                                 const Operators& ops);
/// `lumped`'s costs (lumped_costs.cpp): proportional to the DOF.
SchemeCosts lumpedCosts(const CaseParams& p, const SchemeSizes& sizes);

}  // namespace enamel
