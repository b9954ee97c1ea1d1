#include "isoflex/integrate/time_integrator.hpp"

#include "isoflex/integrate/dae_integrator.hpp"
#include "isoflex/integrate/energy_momentum.hpp"

namespace isoflex::integrate {

std::unique_ptr<TimeIntegrator> make_time_integrator(const system::System& sys,
                                                     const model::Solver& settings) {
  if (settings.integrator == model::Integrator::energy_momentum)
    return std::make_unique<EnergyMomentumIntegrator>(sys, settings);
  return std::make_unique<DaeIntegrator>(sys, settings);
}

}  // namespace isoflex::integrate
