// Event file reading speed: the full parse of events.txt (target >= 20 million events/s on one
// core), a 1% window of a large events.txt (binary search, so it should cost ~1% of a full
// parse or less), and HDF5 reads. Rerun with:
//   build/benchmarks/io_benchmark --benchmark_counters_tabular=true
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <map>
#include <random>
#include <string>

#include "evfs/core/event_stream.h"
#include "evfs/io/event_text.h"
#include "evfs/io/hdf5_io.h"

namespace evfs {
namespace {

constexpr int kSensorWidth = 346;
constexpr int kSensorHeight = 260;
constexpr int kNumEvents = 2000000;

// DAVIS-like events; with `fraction_digits` 6 the timestamps are whole microseconds.
EventStream MakeEvents(int fraction_digits) {
  constexpr uint32_t kSeed = 7;
  // Mean gap between events: 2 M events over ~10 s, a busy DAVIS scene.
  constexpr int64_t kMaxGapNs = 10000;
  std::mt19937 random(kSeed);
  std::uniform_int_distribution<int64_t> gap(0, kMaxGapNs);
  std::uniform_int_distribution<int> x(0, kSensorWidth - 1);
  std::uniform_int_distribution<int> y(0, kSensorHeight - 1);
  std::bernoulli_distribution positive(0.5);
  const int64_t resolution_ns = fraction_digits == 6 ? 1000 : 1;
  EventStream events(kSensorWidth, kSensorHeight);
  events.reserve(kNumEvents);
  int64_t t_ns = 1500000000;
  for (int i = 0; i < kNumEvents; ++i) {
    t_ns += gap(random) / resolution_ns * resolution_ns;
    events.push_back(t_ns, static_cast<uint16_t>(x(random)), static_cast<uint16_t>(y(random)),
                     positive(random) ? 1 : -1);
  }
  return events;
}

// Test files are written once per process and removed at exit.
class BenchmarkFiles {
 public:
  ~BenchmarkFiles() {
    for (const auto& entry : paths_) std::filesystem::remove(entry.second);
  }
  const std::string& EventsText(int fraction_digits) {
    return Get("events_" + std::to_string(fraction_digits) + ".txt", [&](const std::string& path) {
      WriteEventsText(path, MakeEvents(fraction_digits));
    });
  }
  const std::string& EventsHdf5() {
    return Get("events.h5",
               [](const std::string& path) { WriteHdf5(path, MakeEvents(9), {}, {}); });
  }

 private:
  template <typename Writer>
  const std::string& Get(const std::string& name, Writer&& write) {
    auto found = paths_.find(name);
    if (found == paths_.end()) {
      const std::string path = (std::filesystem::temp_directory_path() /
                                ("evfs_io_benchmark_" + std::to_string(::getpid()) + "_" + name))
                                   .string();
      write(path);
      found = paths_.emplace(name, path).first;
    }
    return found->second;
  }

  std::map<std::string, std::string> paths_;
};

BenchmarkFiles& Files() {
  static BenchmarkFiles files;
  return files;
}

void SetEventRate(benchmark::State& state, size_t events_per_iteration) {
  state.counters["events_per_s"] = benchmark::Counter(
      static_cast<double>(events_per_iteration), benchmark::Counter::kIsIterationInvariantRate);
}

void BM_ParseEventsText(benchmark::State& state) {
  const std::string& path = Files().EventsText(static_cast<int>(state.range(0)));
  size_t count = 0;
  for (auto _ : state) {
    const EventStream events = ReadEventsText(path, kSensorWidth, kSensorHeight);
    count = events.size();
    benchmark::DoNotOptimize(events.t_ns().data());
  }
  SetEventRate(state, count);
  state.SetBytesProcessed(static_cast<int64_t>(state.iterations()) *
                          static_cast<int64_t>(std::filesystem::file_size(path)));
}
BENCHMARK(BM_ParseEventsText)->Arg(6)->Arg(9)->Unit(benchmark::kMillisecond);

// A window holding 1% of the events, in the middle of the file.
void BM_ReadEventsWindow(benchmark::State& state) {
  const std::string& path = Files().EventsText(9);
  const EventTextReader reader(path, kSensorWidth, kSensorHeight);
  const EventStream all = reader.ReadAll();
  const size_t first = all.size() / 2;
  const int64_t t_begin_ns = all.t_ns(first);
  const int64_t t_end_ns = all.t_ns(first + all.size() / 100);
  size_t count = 0;
  for (auto _ : state) {
    const EventStream window = reader.Read(t_begin_ns, t_end_ns);
    count = window.size();
    benchmark::DoNotOptimize(window.t_ns().data());
  }
  SetEventRate(state, count);
}
BENCHMARK(BM_ReadEventsWindow)->Unit(benchmark::kMicrosecond);

// Arg 0: all events; arg 1: a 1% window (binary search over /events/ts).
void BM_ReadHdf5(benchmark::State& state) {
  const Hdf5DataSource source(Files().EventsHdf5());
  const bool window = state.range(0) == 1;
  const int64_t middle = source.num_events() / 2;
  const int64_t t_begin_ns = source.ReadEventRange(middle, middle + 1).t_ns(0);
  const int64_t t_end_ns = source
                               .ReadEventRange(middle + source.num_events() / 100,
                                               middle + source.num_events() / 100 + 1)
                               .t_ns(0);
  size_t count = 0;
  for (auto _ : state) {
    const EventStream events =
        window ? source.ReadEvents(t_begin_ns, t_end_ns) : source.ReadAllEvents();
    count = events.size();
    benchmark::DoNotOptimize(events.t_ns().data());
  }
  SetEventRate(state, count);
}
BENCHMARK(BM_ReadHdf5)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace evfs

BENCHMARK_MAIN();
