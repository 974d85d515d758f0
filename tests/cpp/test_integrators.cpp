// The integrators' registry (solver/lib/integrators/registry.cpp): the table of schemes by name is the one the
// `integrator` key offers, each name builds its own scheme, and an unknown name is refused with the list.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "integrators.hpp"
#include "simulation.hpp"

using namespace enamel;

namespace {

CaseParams smallCase(const std::string& integrator) {
  // E_transverse given (not measured) to keep the set-up short.
  return parseCase("theta_D = 30\nEr_over_kd = 10\nsigma_ru_over_sigma0 = 21.4\nE_transverse_over_Er = 0.1\n"
                   "w_s_over_d = 8\nh_s_over_d = 4\nintegrator = \"" + integrator + "\"\n",
                   "integrators", "", {});
}

}  // namespace

TEST(Integrators, RegistryNamesAreTheIntegratorKeysChoices) {
  std::string names;
  std::set<std::string> distinct;
  for (const IntegratorEntry& e : integratorRegistry()) {
    names += (names.empty() ? "" : "|") + std::string(e.name);
    distinct.insert(e.name);
  }
  EXPECT_EQ(distinct.size(), integratorRegistry().size());
  std::string choices;
  for (const KeySpec& k : caseKeys())
    if (std::string(k.name) == "integrator") choices = k.choices;
  EXPECT_EQ(names, choices);
}

TEST(Integrators, EachRegisteredNameBuildsItsSchemeAndAnUnknownOneIsRefused) {
  for (const IntegratorEntry& e : integratorRegistry()) {
    Simulation sim(smallCase(e.name));
    EXPECT_EQ(sim.integrator->name(), e.name);
    EXPECT_GT(sim.integrator->timeStep(), 0);
    CaseParams other = sim.params;
    other.integrator = "leapfrog";
    try {
      makeIntegrator(other, sim.model, sim.materials, sim.ops);
      ADD_FAILURE() << "an unknown integrator was built";
    } catch (const IntegratorError& err) {
      std::string available;  // the registry's names, in its order
      for (const IntegratorEntry& r : integratorRegistry())
        available += std::string(available.empty() ? "" : ", ") + r.name;
      EXPECT_NE(std::string(err.what()).find("'leapfrog' is not available in this build (available: " + available + ")"),
                std::string::npos)
          << err.what();
    }
  }
}
