// Timing of live haptic sessions: the servo loop (realtime/haptics) at 1, 2, 4 and 8 kHz with the
// fracture and edge models, against an emulated device over loopback UDP whose simulated hand makes the
// full approach–rupture–cut–retreat cycle of tests/realtime/haptics/haptic_quick_cut.toml (about
// 2.6 s per session), plus paper 001's arrangement (device 2 kHz, model thread 1 kHz). Each
// benchmark is one session; its counters are the session's wake-up lateness, period jitter and
// model compute percentiles [us], and its overruns. SCHED_FIFO and mlockall are requested (the
// `fifo` counter says whether they were granted).
//
//   ./build/experiments/benchmarks/bench_haptics_session
//   ./build/experiments/benchmarks/bench_haptics_session --benchmark_filter='fracture/4000'

#include "experiments/models/model_catalogue.hpp"
#include "experiments/models/run_model.hpp"
#include "formats/scene/scene_mesh.hpp"
#include "formats/scene/scene_reader.hpp"
#include "realtime/haptics/device_emulator.hpp"
#include "realtime/haptics/servo_loop.hpp"
#include "realtime/haptics/udp_device.hpp"

#include <benchmark/benchmark.h>

#include <thread>

using namespace kerf;

namespace {

void session(benchmark::State& state, const std::string& model_name) {
  const double rate = static_cast<double>(state.range(0));
  const double model_rate = static_cast<double>(state.range(1));
  const Scene scene = read_scene(std::filesystem::path(KERF_SOURCE_DIR) / "tests/realtime/haptics/haptic_quick_cut.toml");
  const TetMesh mesh = scene_mesh(scene);
  const SampledTrajectory target = sample_scene_trajectories(scene).front();
  ServoReport report;
  for (auto _ : state) {
    BuiltModel model = make_model(model_name, scene, mesh);
    EmulatedDeviceSettings device;
    for (const ToolState& s : target.samples) device.target.push_back(s.position);
    device.target_rate = target.rate;
    device.rate = rate;
    device.hand.stiffness = 3000.0;
    device.hold = 0.3;
    device.tail = 0.3;
    DeviceEmulator emulator(device);
    std::atomic<bool> stop{false};
    std::thread emulator_thread([&] { emulator.run(stop); });
    UdpDevice link("127.0.0.1", emulator.port());
    HapticDevice* devices[] = {&link};
    ServoSettings settings;
    settings.rate = rate;
    settings.model_rate = model_rate;
    settings.duration = 0.3 + target.duration() + 0.3;
    settings.safety = {8.5, 1000.0, 0.2, 0.05};
    ServoLoop loop(*model.model, devices, settings, nullptr);
    report = loop.run();
    stop = true;
    emulator_thread.join();
  }
  const TimingStatistics& t = report.timing;
  const DurationHistogram& compute = model_rate > 0.0 ? report.model_timing.compute : t.compute;
  state.counters["ticks"] = static_cast<double>(t.ticks);
  state.counters["overruns"] = static_cast<double>(t.overruns);
  state.counters["late_p50_us"] = t.lateness.percentile(50) * 1e6;
  state.counters["late_p99_us"] = t.lateness.percentile(99) * 1e6;
  state.counters["late_p999_us"] = t.lateness.percentile(99.9) * 1e6;
  state.counters["late_max_us"] = t.lateness.max() * 1e6;
  state.counters["jitter_p99_us"] = t.period_jitter.percentile(99) * 1e6;
  state.counters["jitter_max_us"] = t.period_jitter.max() * 1e6;
  state.counters["compute_p50_us"] = compute.percentile(50) * 1e6;
  state.counters["compute_p99_us"] = compute.percentile(99) * 1e6;
  state.counters["compute_max_us"] = compute.max() * 1e6;
  state.counters["fifo"] = report.realtime.fifo ? 1.0 : 0.0;
}

} // namespace

BENCHMARK_CAPTURE(session, fracture, std::string("fracture"))
    ->Args({1000, 0})
    ->Args({2000, 0})
    ->Args({4000, 0})
    ->Args({8000, 0})
    ->Args({2000, 1000})
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

BENCHMARK_CAPTURE(session, edge, std::string("edge"))
    ->Args({1000, 0})
    ->Args({2000, 0})
    ->Args({4000, 0})
    ->Args({8000, 0})
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

BENCHMARK_MAIN();
