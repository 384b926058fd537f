// BM_Erk4Sensitivities/<model>: one ERK4 step with A = ∂F/∂x and B = ∂F/∂u.
#include <benchmark/benchmark.h>

#include <random>

#include "core/numerics/integrator_erk4.hpp"
#include "models/crazyflie.hpp"
#include "models/mikrokopter.hpp"
#include "models/pendubot.hpp"
#include "tests/random_states.hpp"

namespace mixpilot {
namespace {

template <class M>
void BM_Erk4Sensitivities(benchmark::State& state, double dt) {
  const M model;
  const IntegratorErk4<M> erk4(model);
  std::mt19937 rng(7);
  typename M::State x = testing_states::random_state(model, rng), xn;
  const typename M::Input u = testing_states::random_input(model, rng);
  typename IntegratorErk4<M>::MatA A;
  typename IntegratorErk4<M>::MatB B;
  for (auto _ : state) {
    benchmark::DoNotOptimize(x.data());
    erk4.step(x, u, dt, xn, A, B);
    benchmark::DoNotOptimize(xn.data());
    benchmark::DoNotOptimize(A.data());
    benchmark::DoNotOptimize(B.data());
    benchmark::ClobberMemory();
  }
}

// Each at its controller's step: Pendubot 2 ms (SPEC §5.1), quadrotors 15 ms.
void pendubot(benchmark::State& s) { BM_Erk4Sensitivities<models::Pendubot>(s, 0.002); }
void crazyflie(benchmark::State& s) { BM_Erk4Sensitivities<models::Crazyflie>(s, 0.015); }
void mikrokopter(benchmark::State& s) { BM_Erk4Sensitivities<models::MikroKopter>(s, 0.015); }
BENCHMARK(pendubot)->Name("BM_Erk4Sensitivities/pendubot");
BENCHMARK(crazyflie)->Name("BM_Erk4Sensitivities/crazyflie");
BENCHMARK(mikrokopter)->Name("BM_Erk4Sensitivities/mikrokopter");

}  // namespace
}  // namespace mixpilot
