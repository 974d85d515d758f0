// The integrators' registry (solver/lib/integrators/registry.cpp): one row per enumerator of IntegratorScheme (the
// `integrator` key's choices, choices.hpp), in order; each builds its own scheme, and a value without a row is
// refused with the list.
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

TEST(Integrators, RegistryHasOneRowPerIntegratorChoiceInOrder) {
  const auto& names = enumNames<IntegratorScheme>();
  ASSERT_EQ(integratorRegistry().size(), names.size());
  for (std::size_t i = 0; i < names.size(); ++i)
    EXPECT_EQ(nameOf(integratorRegistry()[i].scheme), names[i]) << "row " << i;
  std::string choices;
  for (const KeySpec& k : caseKeys())
    if (std::string(k.name) == "integrator") choices = k.choices;
  EXPECT_EQ(splitEnumNames(choices), names) << "the integrator key's choices are IntegratorScheme's names";
  EXPECT_EQ(smallCase("lumped").integrator, IntegratorScheme::lumped);
}

TEST(Integrators, EachRegisteredSchemeBuildsItselfAndOneWithoutARowIsRefused) {
  for (const IntegratorEntry& e : integratorRegistry()) {
    Simulation sim(smallCase(nameOf(e.scheme)));
    EXPECT_EQ(sim.integrator->name(), nameOf(e.scheme));
    EXPECT_GT(sim.integrator->timeStep(), 0);
    CaseParams other = sim.params;
    other.integrator = static_cast<IntegratorScheme>(enumNames<IntegratorScheme>().size());  // no row, no name
    try {
      makeIntegrator(other, sim.model, sim.materials, sim.ops);
      ADD_FAILURE() << "an integrator without a row was built";
    } catch (const IntegratorError& err) {
      std::string available;  // the registry's names, in its order
      for (const IntegratorEntry& r : integratorRegistry())
        available += (available.empty() ? "" : ", ") + nameOf(r.scheme);
      EXPECT_NE(std::string(err.what()).find("'?' is not available in this build (available: " + available + ")"),
                std::string::npos)
          << err.what();
    }
  }
}
