// vrflow-bench-fluid: see CMakeLists.txt. `--quick` runs few steps (a smoke run); `--steps N`
// sets the timed steps of the small grid (the large one runs a quarter, at least 4);
// `--small-only` leaves out 64 x 128 x 64. Every case runs with both preconditioners, MIC(0)
// (the solver before multigrid) first; `--preconditioner NAME` keeps one, `--one-thread` keeps
// the cases of one rank of one thread. `--baseline-bin DIR` runs DIR/vrflow-fluid-blocks (another
// build, e.g. main's) right before this build's on every case, so that before and after see the
// same load (lines with "code": "baseline" / "this", and this build's speed-up over the
// baseline's); `--rounds N` repeats every case N times.
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

namespace {

std::string binDir() {
  char path[4096];
  const ssize_t n = readlink("/proc/self/exe", path, sizeof path - 1);
  if (n <= 0) return ".";
  path[n] = '\0';
  std::string p(path);
  return p.substr(0, p.rfind('/'));
}

std::string machine() {
  std::ifstream in("/proc/cpuinfo");
  std::string line, model = "unknown CPU";
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      model = line.substr(line.find(':') + 2);
      break;
    }
  }
  return model + ", " + std::to_string(std::thread::hardware_concurrency()) + " cores";
}

// STREAM "copy": c[i] = a[i] over arrays far larger than the caches; bytes moved = 2 x 8 x n per
// pass (read a, write c), best of 5 passes.
double streamCopyGBs() {
  const std::size_t n = 1u << 24;  // 128 MiB per array
  std::vector<double> a(n, 1.0), c(n, 0.0);
  double best = 1e30;
  for (int pass = 0; pass < 5; ++pass) {
    const auto t0 = std::chrono::steady_clock::now();
    std::memcpy(c.data(), a.data(), n * sizeof(double));
    const auto t1 = std::chrono::steady_clock::now();
    best = std::min(best, std::chrono::duration<double>(t1 - t0).count());
    a[pass] = c[n - 1 - static_cast<std::size_t>(pass)] + 1.0;  // keep the copies observable
  }
  return 2.0 * 8.0 * static_cast<double>(n) / best / 1e9;
}

nlohmann::json runCase(const std::string& program, int nx, int ny, int nz, int bodies, int ranks,
                       int threads, int steps, const char* preconditioner) {
  std::string cmd = std::string(VRFLOW_MPIEXEC) + " --oversubscribe -np " + std::to_string(ranks);
  if (geteuid() == 0) cmd += " --allow-run-as-root";
  // mpirun binds each rank to one core: a rank's threads would then share that core (oneTBB
  // starts no worker for a mask of one CPU).
  if (threads > 1) cmd += " --bind-to none";
  cmd += " " + program + " --nx " + std::to_string(nx) + " --ny " + std::to_string(ny) + " --nz " +
         std::to_string(nz) + " --h " + std::to_string(1.0 / nx) +
         " --dt 0.005 --warmup 3 --steps " + std::to_string(steps + 3) + " --bodies " +
         std::to_string(bodies) + " --threads " + std::to_string(threads) +
         " --max-particles 2000000 --preconditioner " + preconditioner;
  // The coupled case: the boxes start in the liquid (floating and sinking), so every timed step
  // couples them; dropped from above they were still in air over the whole timed window.
  if (bodies > 0) cmd += " --bodies-in-liquid";
  FILE* pipe = popen(cmd.c_str(), "r");
  if (!pipe) return {};
  std::string out;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, pipe)) out += buf;
  const int status = pclose(pipe);
  const auto start = out.find('{');
  if (status != 0 || start == std::string::npos) {
    std::fprintf(stderr, "vrflow-bench-fluid: '%s' failed (status %d): %s\n", cmd.c_str(), status,
                 out.c_str());
    return {};
  }
  return nlohmann::json::parse(out.substr(start, out.find('\n', start) - start));
}

// The machine's 1-minute load average when a case ends (other work on the cores).
double loadAverage() {
  std::ifstream in("/proc/loadavg");
  double load = -1.0;
  in >> load;
  return load;
}

}  // namespace

int main(int argc, char** argv) {
  int steps = 30, rounds = 1;
  bool smallOnly = false, oneThread = false;
  std::string onlyPreconditioner, baseline;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--quick") == 0) {
      steps = 4;
    } else if (std::strcmp(argv[i], "--small-only") == 0) {
      smallOnly = true;
    } else if (std::strcmp(argv[i], "--one-thread") == 0) {
      oneThread = true;
    } else if (std::strcmp(argv[i], "--steps") == 0 && i + 1 < argc) {
      steps = std::max(1, std::atoi(argv[++i]));
    } else if (std::strcmp(argv[i], "--rounds") == 0 && i + 1 < argc) {
      rounds = std::max(1, std::atoi(argv[++i]));
    } else if (std::strcmp(argv[i], "--preconditioner") == 0 && i + 1 < argc &&
               (std::strcmp(argv[i + 1], "mic0") == 0 ||
                std::strcmp(argv[i + 1], "multigrid") == 0)) {
      onlyPreconditioner = argv[++i];
    } else if (std::strcmp(argv[i], "--baseline-bin") == 0 && i + 1 < argc) {
      baseline = std::string(argv[++i]) + "/vrflow-fluid-blocks";
      if (access(baseline.c_str(), X_OK) != 0) {
        std::fprintf(stderr, "vrflow-bench-fluid: --baseline-bin: no program %s\n",
                     baseline.c_str());
        return 2;
      }
    } else {
      std::fprintf(stderr,
                   "usage: vrflow-bench-fluid [--quick] [--steps N] [--small-only] [--one-thread] "
                   "[--preconditioner mic0|multigrid] [--rounds N] [--baseline-bin DIR]\n");
      return 2;
    }
  }
  const std::string program = binDir() + "/vrflow-fluid-blocks";
  setenv("OMPI_MCA_btl", "self,vader", 0);
  setenv("OMPI_MCA_btl_vader_single_copy_mechanism", "none", 0);
  // Ranks yield while they wait: on a shared 2-core machine busy-polling ranks starve each other.
  setenv("OMPI_MCA_mpi_yield_when_idle", "1", 0);
  const std::string where = machine();
  int failures = 0;
  struct Grid {
    int nx, ny, nz;
  };
  // One case of one program: its line, or an empty object when it failed.
  auto measure = [&](const std::string& prog, int nx, int ny, int nz, int bodies, int ranks,
                     int threads, int n, const char* preconditioner) {
    // The copy is measured right before each case, so both see the same machine load.
    const double stream = streamCopyGBs();
    auto result = runCase(prog, nx, ny, nz, bodies, ranks, threads, n, preconditioner);
    nlohmann::json line;
    if (result.empty()) {
      ++failures;
      return line;
    }
    line["grid"] = result["grid"];
    line["rigid"] = bodies;
    line["ranks"] = ranks;
    line["threads"] = threads;
    line["preconditioner"] = preconditioner;
    line["ms_per_step"] = result["ms_per_step"];
    // The process's CPU time (all its threads): on a loaded machine it tells the work done
    // from the time spent waiting for a core.
    line["cpu_ms_per_step"] = result["cpu_ms_per_step"];
    line["cg_iterations"] = result["cg_iterations"];
    line["pressure_ms_per_step"] = result["pressure_ms_per_step"];
    line["bandwidth_gbs"] = result["bandwidth_gbs"];
    line["stream_copy_gbs"] = stream;
    // The CG's estimated traffic rate as a fraction of the copy's (above 1: vectors stay in
    // cache).
    line["bandwidth_vs_stream"] = stream > 0 ? result["bandwidth_gbs"].get<double>() / stream : 0.0;
    line["particles"] = result["particles"];
    line["digest"] = result["digest"];
    line["volume"] = result["volume"];
    // Every box must be in the liquid from the first timed step on, or the case measures
    // the fluid alone.
    line["wet_bodies_first_timed"] = result["wet_bodies_first_timed"];
    if (result["wet_bodies_first_timed"].get<int>() != bodies) {
      std::fprintf(stderr, "vrflow-bench-fluid: %d of %d bodies wet when timing started\n",
                   result["wet_bodies_first_timed"].get<int>(), bodies);
      ++failures;
    }
    line["steps"] = n;
    line["machine"] = where;
    line["load_average"] = loadAverage();
    return line;
  };
  auto print = [](const nlohmann::json& line) {
    std::printf("%s\n", line.dump().c_str());
    std::fflush(stdout);
  };
  for (int round = 1; round <= rounds; ++round) {
    for (const Grid g : {Grid{32, 64, 32}, Grid{64, 128, 64}}) {
      if (smallOnly && g.nx != 32) continue;
      for (int bodies : {0, 20}) {
        double baselineMs = 0.0;
        // One rank of one thread (the serial solver: the same bits as before threads), then the
        // block's two threads, then two ranks of one thread each.
        struct Split {
          int ranks, threads;
        };
        for (const Split split : {Split{1, 1}, Split{1, 2}, Split{2, 1}}) {
          if (oneThread && (split.ranks != 1 || split.threads != 1)) continue;
          double mic0Ms = 0.0;
          for (const char* preconditioner : {"mic0", "multigrid"}) {
            if (!onlyPreconditioner.empty() && onlyPreconditioner != preconditioner) continue;
            const int n = g.nx == 32 ? steps : std::max(4, steps / 4);
            nlohmann::json before;
            if (!baseline.empty()) {
              before = measure(baseline, g.nx, g.ny, g.nz, bodies, split.ranks, split.threads, n,
                               preconditioner);
              if (!before.empty()) {
                before["code"] = "baseline";
                before["round"] = round;
                print(before);
              }
            }
            auto line = measure(program, g.nx, g.ny, g.nz, bodies, split.ranks, split.threads, n,
                                preconditioner);
            if (line.empty()) continue;
            const double ms = line["ms_per_step"].get<double>();
            // Speed-ups against one rank of one thread with MIC(0) (the solver before
            // multigrid), and against MIC(0) with the same split.
            if (split.ranks == 1 && split.threads == 1 && mic0Ms == 0.0) baselineMs = ms;
            if (baselineMs > 0 && ms > 0 && baselineMs != ms) {
              line["speedup_vs_1_rank_1_thread"] = baselineMs / ms;
            }
            if (mic0Ms == 0.0) {
              mic0Ms = ms;
            } else if (ms > 0) {
              line["speedup_vs_mic0"] = mic0Ms / ms;
            }
            if (!before.empty() && ms > 0) {
              line["code"] = "this";
              line["speedup_vs_baseline"] = before["ms_per_step"].get<double>() / ms;
              line["cpu_speedup_vs_baseline"] =
                  before["cpu_ms_per_step"].get<double>() / line["cpu_ms_per_step"].get<double>();
            }
            line["round"] = round;
            print(line);
          }
        }
      }
    }
  }
  return failures == 0 ? 0 : 1;
}
