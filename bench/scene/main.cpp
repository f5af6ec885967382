// vrflow-bench-scene: iterations per second of the demo scene without rendering, in three forms
// run one after the other on the same machine:
//   "network"      the vrflow network (examples/paper_scene without its viewer): every module its
//                  own process, messages through the daemon, started by `vrflow run`; the
//                  net's collision and rigid/net interactors run beside the animators on
//                  states one iteration old, as the demo ships (section 4.2 of the paper);
//   "network-sequential" the same with every interactor after its animators, the loop's order;
//   "monolithic"   the same solver classes called in one loop in one process;
//   "monolithic-springs-once-a-step" (20 objects) the same loop with the net's springs applied
//                  once per step from outside, as the demo did before issue 26 (unstable);
//   "bullet-world" Bullet's own btDiscreteDynamicsWorld stepping the same rigid bodies (no net:
//                  Bullet's soft bodies are another solver, so only the rigid part compares).
// The scene of 20 objects is the demo's (rigid objects and the 20 x 20 net); 200 and 2000 are
// the rigid package's `boxes:N` scenes (rigid bodies only, in all three forms).
// The network and the loop are measured alternately, `--rounds` times, so that a machine loaded
// by other work slows both alike; each line says its round, and a last line per scene gives the
// median of the rounds' ratios. `--baseline-bin DIR` also runs the network with the programs of
// another build (DIR is its bin/ folder, e.g. the main branch's), as "network-baseline", in the
// same rounds: before and after in one run.
// One JSON line per result: {"variant": V, "objects": N, "iterations_per_s": X, ...};
// lines add "cpu_ms_per_iteration" (for the network: every process of the run, the daemon's
// included; for the loop: its thread) and the load average; network lines add
// "cpu_of_monolithic", their CPU time over the loop's of the same round: what the network adds
// in work, which a loaded machine disturbs less than the wall-clock ratio.
// Lines also carry "median_iteration_us": for the loop the median of its steps' wall times, for
// the network the median time between consecutive iterations of the bodies' animator (from a
// trace of the longer run, the measured iterations only); network lines add
// "median_of_monolithic", the loop's median over the network's: the wall-clock ratio of a
// typical iteration, which the other processes of a loaded machine disturb only in the
// iterations they preempt (the mean-based "of_monolithic" pays for every preemption).
#include <btBulletDynamicsCommon.h>
#include <sys/resource.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "vrflow/app/loader.hpp"
#include "vrflow/app/writer.hpp"
#include "vrflow/massspring/contact.hpp"
#include "vrflow/massspring/net.hpp"
#include "vrflow/massspring/solver.hpp"
#include "vrflow/rigid/scene.hpp"
#include "vrflow/rigid/world.hpp"

namespace fs = std::filesystem;
using namespace vrflow;

namespace {

using Clock = std::chrono::steady_clock;
constexpr double kDt = 0.01;
const msg::Vec3 kGravity{0, -9.81, 0};

struct Context {
  fs::path bin;       // build/bin
  fs::path baseline;  // another build's bin/, or empty
  fs::path source;    // the repository
  fs::path work;      // scratch folder
};

std::string quote(const std::string& s) {
  return "'" + s + "'";
}

// The parameters of the demo's net, as examples/paper_scene/paper_scene.xml sets them.
massspring::GridParams demoGrid() {
  massspring::GridParams grid;
  grid.n = 20;
  grid.m = 20;
  grid.spacing = 0.1;
  grid.mass = 8;
  grid.stiffness = 300;
  grid.damping = 0.2;
  grid.origin = {1.25, 0.95, 0};
  return grid;
}

Result<std::vector<rigid::Body>> bodiesFor(const Context& ctx, int objects) {
  if (objects == 20)
    return rigid::loadScene((ctx.source / "examples/paper_scene/scene.json").string());
  return rigid::generateScene("boxes:" + std::to_string(objects));
}

// The network's application: the demo scene without its viewer, or the rigid network of figure 4
// (animator, force field, rigid interactor) for the boxes scenes.
// `sequential`: the net's interactors get no initial message either, so every interactor runs
// after its animators within the iteration (the monolithic loop's order) instead of beside them.
Result<std::string> networkApp(const Context& ctx, int objects, bool sequential) {
  auto loaded =
      app::loadApplicationFile((ctx.source / "examples/paper_scene/paper_scene.xml").string());
  if (!loaded) return loaded.error();
  app::Application application = std::move(loaded).value();
  const std::set<std::string> keep =
      objects == 20 ? std::set<std::string>{"bodies",  "contacts",       "field",       "net",
                                            "springs", "net-collisions", "net-contacts"}
                    : std::set<std::string>{"bodies", "contacts", "field"};
  std::erase_if(application.modules, [&](const app::Module& m) { return !keep.contains(m.id); });
  std::erase_if(application.connections, [&](const app::Connection& c) {
    return !keep.contains(c.from.node) || !keep.contains(c.to.node);
  });
  for (auto& module : application.modules) {
    std::erase_if(module.params, [](const app::Param& p) { return p.name == "state-file"; });
    if (sequential && module.id != "bodies" && module.id != "net") module.inputs.clear();
    if (module.id != "bodies") continue;
    for (auto& p : module.params) {
      if (p.name == "scene" && objects != 20)
        p = {"generate", "boxes:" + std::to_string(objects), p.loc};
      if (p.name == "scene" && objects == 20)
        p.value = (ctx.source / "examples/paper_scene/scene.json").string();
    }
  }
  const fs::path file =
      ctx.work / ("scene-" + std::to_string(objects) + (sequential ? "-sequential" : "") + ".xml");
  if (auto saved = app::saveApplicationFile(application, file.string()); !saved)
    return saved.error();
  return file.string();
}

// CPU seconds (user + system) of `who` (RUSAGE_CHILDREN: every waited-for descendant).
double cpuSeconds(int who) {
  rusage usage{};
  getrusage(who, &usage);
  auto seconds = [](const timeval& t) {
    return static_cast<double>(t.tv_sec) + static_cast<double>(t.tv_usec) * 1e-6;
  };
  return seconds(usage.ru_utime) + seconds(usage.ru_stime);
}

struct Timing {
  double wallSeconds = 0;
  double cpuSeconds = 0;
};

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n == 0 ? 0 : n % 2 == 1 ? values[n / 2] : (values[n / 2 - 1] + values[n / 2]) / 2;
}

// The median time (us) between the starts of consecutive iterations of `module`, from iteration
// `first` on, in a trace written by `vrflow run --trace`; 0 if the trace has too few.
double medianPeriodUs(const fs::path& trace, const std::string& module, int first) {
  std::ifstream in(trace);
  const auto json = nlohmann::json::parse(in, nullptr, false);
  if (json.is_discarded() || !json.contains("traceEvents")) return 0;
  int tid = -1;
  for (const auto& e : json["traceEvents"])
    if (e.value("ph", "") == "M" && e.value("name", "") == "thread_name" &&
        e["args"].value("name", "") == module)
      tid = e["tid"].get<int>();
  std::map<std::uint64_t, double> starts;  // by iteration
  for (const auto& e : json["traceEvents"]) {
    if (e.value("ph", "") != "X" || e.value("name", "") != "compute" || e.value("tid", -2) != tid)
      continue;
    const auto iteration = e["args"].value("iteration", std::uint64_t{0});
    if (iteration >= static_cast<std::uint64_t>(first)) starts[iteration] = e["ts"].get<double>();
  }
  std::vector<double> periods;
  for (auto it = starts.begin(); it != starts.end() && std::next(it) != starts.end(); ++it)
    if (std::next(it)->first == it->first + 1)
      periods.push_back(std::next(it)->second - it->second);
  return periods.size() < 2 ? 0 : median(periods);
}

// Wall time of `vrflow run` for `iterations`, from its report (spawning included), and the CPU
// time of all its processes, with the programs of `bin`.
// With `trace`, the run also writes its trace there.
Result<Timing> runNetwork(const Context& ctx, const fs::path& bin, const std::string& appFile,
                          int iterations, const fs::path& trace = {}) {
  const fs::path report = ctx.work / "report.json";
  fs::remove(report);
  const std::string command =
      "cd " + quote(ctx.work.string()) + " && " + quote((bin / "vrflow").string()) + " run " +
      quote(appFile) + " -n " + std::to_string(iterations) + " --no-progress --report " +
      quote(report.string()) + (trace.empty() ? "" : " --trace " + quote(trace.string())) +
      " > run.log 2>&1";
  const double cpuBefore = cpuSeconds(RUSAGE_CHILDREN);
  if (const int status = std::system(command.c_str()); status != 0) {
    return makeError("vrflow run failed (status " + std::to_string(status) + "); see " +
                     (ctx.work / "run.log").string());
  }
  std::ifstream in(report);
  const auto json = nlohmann::json::parse(in, nullptr, false);
  if (json.is_discarded() || !json.contains("timing")) return makeError("unreadable report");
  return Timing{json["timing"]["wall_s"].get<double>(), cpuSeconds(RUSAGE_CHILDREN) - cpuBefore};
}

struct Rate {
  double perSecond = 0;
  double cpuMsPerIteration = 0;
  double medianIterationUs = 0;  ///< see the file's comment; 0 if unknown
};

// Steady-state rate of the network: the difference of two runs of different lengths cancels the
// start-up (spawning processes, loading the scene) and the shutdown.
Result<Rate> networkRate(const Context& ctx, const fs::path& bin, int objects, bool sequential,
                         int warm, int measured) {
  auto appFile = networkApp(ctx, objects, sequential);
  if (!appFile) return appFile.error();
  auto shorter = runNetwork(ctx, bin, *appFile, warm);
  if (!shorter) return shorter.error();
  const fs::path trace = ctx.work / "trace.json";
  fs::remove(trace);
  auto longer = runNetwork(ctx, bin, *appFile, warm + measured, trace);
  if (!longer) return longer.error();
  const double seconds = longer->wallSeconds - shorter->wallSeconds;
  if (seconds <= 0) return makeError("the longer run was not longer; the machine is too noisy");
  return Rate{measured / seconds, 1e3 * (longer->cpuSeconds - shorter->cpuSeconds) / measured,
              medianPeriodUs(trace, "bodies", warm)};
}

// The same solvers in one loop: what one iteration of the network computes, in the network's
// order (interactors see the state of the previous step, then the animators integrate).
class Monolithic {
 public:
  /// `springsOnceAStep`: the net's springs as the demo applied them until issue 26 (the spring
  /// interactor's forces once per 10 ms step, one sub-step: unstable, omega dt 3.0) instead of
  /// the animator's own springs in 3 sub-steps.
  Status init(std::vector<rigid::Body> bodies, bool withNet, bool springsOnceAStep = false) {
    rigid::ContactParams contact;
    contact.gravity = kGravity;
    world_ = std::make_unique<rigid::RigidWorld>(
        rigid::ForceField({rigid::FieldTerm{rigid::FieldTerm::Kind::Gravity, kGravity}}), contact);
    if (auto added = world_->add(bodies); !added) return added;
    if (!withNet) return {};
    auto net = massspring::generateGrid(demoGrid());
    if (!net) return net.error();
    nets_[kNetId] = std::move(net).value();
    options_.dt = kDt;
    options_.substeps = springsOnceAStep ? 1 : 3;
    options_.internalSprings = !springsOnceAStep;
    options_.gravity = kGravity;
    collision_.thickness = 0.05;
    collision_.dt = kDt;
    touch_.dt = kDt;
    return {};
  }

  void step() {
    if (!nets_.empty()) {
      std::map<std::uint64_t, massspring::RigidBody> rigids;
      for (const rigid::Body& b : world_->state().bodies()) {
        rigids[b.id] = {b.position,
                        b.orientation,
                        b.linearVelocity,
                        b.angularVelocity,
                        b.kinematic ? 0.0 : b.mass,
                        b.shape};
      }
      massspring::Net& net = nets_[kNetId];
      std::vector<double> forces(net.positions.size(), 0.0);
      if (!options_.internalSprings) massspring::addSpringForces(net, forces);
      const auto collisions = massspring::netCollisions(nets_, collision_, &collisionMemory_);
      const auto touches = massspring::rigidContacts(nets_, rigids, touch_, &touchMemory_);
      for (const auto* contact : {&collisions, &touches}) {
        if (auto found = contact->nodeForces.find(kNetId); found != contact->nodeForces.end()) {
          for (std::size_t i = 0; i < forces.size(); ++i) forces[i] += found->second[i];
        }
      }
      for (const auto& [id, event] : touches.rigidForces) world_->state().applyForce(id, event);
      world_->step(kDt);
      massspring::step(net, forces, options_);
    } else {
      world_->step(kDt);
    }
  }

 private:
  static constexpr std::uint64_t kNetId = 1ull << 40;
  std::unique_ptr<rigid::RigidWorld> world_;
  std::map<std::uint64_t, massspring::Net> nets_;
  massspring::StepOptions options_;
  massspring::ContactParams collision_, touch_;
  massspring::ContactMemory collisionMemory_, touchMemory_;
};

// Bullet's own world with the same rigid bodies, 20 solver iterations like our interactor.
class BulletWorld {
 public:
  BulletWorld()
      : dispatcher_(&configuration_),
        world_(&dispatcher_, &broadphase_, &solver_, &configuration_) {
    world_.setGravity(
        btVector3(btScalar(kGravity[0]), btScalar(kGravity[1]), btScalar(kGravity[2])));
    world_.getSolverInfo().m_numIterations = 20;
  }
  ~BulletWorld() {
    for (auto& body : bodies_) world_.removeRigidBody(body.get());
  }

  void add(const rigid::Body& b) {
    std::unique_ptr<btCollisionShape> shape;
    const msg::Shape& s = b.shape;
    switch (s.kind) {
      case msg::ShapeKind::Sphere:
        shape = std::make_unique<btSphereShape>(btScalar(s.radius));
        break;
      case msg::ShapeKind::Box:
        shape = std::make_unique<btBoxShape>(btVector3(
            btScalar(s.halfExtents[0]), btScalar(s.halfExtents[1]), btScalar(s.halfExtents[2])));
        break;
      case msg::ShapeKind::Capsule:
        shape = std::make_unique<btCapsuleShape>(btScalar(s.radius), btScalar(2 * s.halfHeight));
        break;
      default: {
        auto hull = std::make_unique<btConvexHullShape>();
        for (std::size_t i = 0; i + 2 < s.vertices.size(); i += 3) {
          hull->addPoint(btVector3(btScalar(s.vertices[i]), btScalar(s.vertices[i + 1]),
                                   btScalar(s.vertices[i + 2])),
                         false);
        }
        hull->recalcLocalAabb();
        shape = std::move(hull);
      }
    }
    const btScalar mass = b.kinematic ? btScalar(0) : btScalar(b.mass);
    btVector3 inertia(0, 0, 0);
    if (mass > 0)
      inertia = btVector3(btScalar(b.inertia[0]), btScalar(b.inertia[4]), btScalar(b.inertia[8]));
    btTransform pose;
    pose.setOrigin(
        btVector3(btScalar(b.position[0]), btScalar(b.position[1]), btScalar(b.position[2])));
    pose.setRotation(btQuaternion(btScalar(b.orientation[0]), btScalar(b.orientation[1]),
                                  btScalar(b.orientation[2]), btScalar(b.orientation[3])));
    motions_.push_back(std::make_unique<btDefaultMotionState>(pose));
    btRigidBody::btRigidBodyConstructionInfo info(mass, motions_.back().get(), shape.get(),
                                                  inertia);
    info.m_friction = btScalar(0.6);
    info.m_restitution = btScalar(0.3);
    bodies_.push_back(std::make_unique<btRigidBody>(info));
    world_.addRigidBody(bodies_.back().get());
    shapes_.push_back(std::move(shape));
  }

  void step() { world_.stepSimulation(btScalar(kDt), 0); }

 private:
  btDefaultCollisionConfiguration configuration_;
  btCollisionDispatcher dispatcher_;
  btDbvtBroadphase broadphase_;
  btSequentialImpulseConstraintSolver solver_;
  btDiscreteDynamicsWorld world_;
  std::vector<std::unique_ptr<btCollisionShape>> shapes_;
  std::vector<std::unique_ptr<btDefaultMotionState>> motions_;
  std::vector<std::unique_ptr<btRigidBody>> bodies_;
};

// Steps `warm` times, then times `measured` steps (wall and this thread's CPU time).
template <typename Step>
Rate loopRate(Step&& step, int warm, int measured) {
  for (int i = 0; i < warm; ++i) step();
  std::vector<double> steps;
  steps.reserve(static_cast<std::size_t>(measured));
  const double cpuBefore = cpuSeconds(RUSAGE_THREAD);
  const auto start = Clock::now();
  for (int i = 0; i < measured; ++i) {
    const auto before = Clock::now();
    step();
    steps.push_back(std::chrono::duration<double, std::micro>(Clock::now() - before).count());
  }
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  return Rate{measured / wall, 1e3 * (cpuSeconds(RUSAGE_THREAD) - cpuBefore) / measured,
              median(std::move(steps))};
}

// The 1-minute load average (other work on the machine), or -1.
double loadAverage() {
  double load[1];
  return getloadavg(load, 1) == 1 ? load[0] : -1;
}

void print(const std::string& variant, int objects, double rate, const std::string& extra = {}) {
  std::printf("{\"variant\":\"%s\",\"objects\":%d,\"iterations_per_s\":%.1f%s}\n", variant.c_str(),
              objects, rate, extra.c_str());
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App cli{"vrflow-bench-scene: the demo scene as a network, in one loop, and in Bullet"};
  bool quick = false;
  int rounds = 3;
  std::string baseline;
  std::vector<int> sizes{20, 200, 2000};
  cli.add_flag("--quick", quick, "Few iterations, 20 and 200 objects (checks the benchmark runs)");
  cli.add_option("--objects", sizes, "Scene sizes: 20 (the demo scene), or N boxes");
  cli.add_option("--rounds", rounds, "Network and loop measured alternately this many times")
      ->check(CLI::Range(1, 100));
  cli.add_option("--baseline-bin", baseline,
                 "Another build's bin/ folder: its network runs as 'network-baseline'")
      ->check(CLI::ExistingDirectory);
  CLI11_PARSE(cli, argc, argv);
  if (quick) sizes = {20, 200};

  Context ctx;
  ctx.bin = fs::canonical("/proc/self/exe").parent_path();
  ctx.source = VRFLOW_SOURCE_DIR;
  ctx.work = fs::temp_directory_path() / ("vrflow-bench-scene-" + std::to_string(::getpid()));
  if (!baseline.empty()) {
    ctx.baseline = fs::canonical(baseline);
    if (!fs::exists(ctx.baseline / "vrflow")) {
      std::fprintf(stderr, "vrflow-bench-scene: --baseline-bin %s: no 'vrflow' program there\n",
                   baseline.c_str());
      return 2;
    }
  }
  fs::create_directories(ctx.work);

  int failures = 0;
  for (const int objects : sizes) {
    // Steps before and during the measurement; the window covers falling, impacts and rest.
    const int measured = quick            ? (objects <= 20 ? 200 : 60)
                         : objects <= 20  ? 600
                         : objects <= 200 ? 200
                                          : 30;
    const int warm = quick ? 10 : objects <= 200 ? 50 : 10;
    auto bodies = bodiesFor(ctx, objects);
    if (!bodies) {
      std::fprintf(stderr, "vrflow-bench-scene: %s\n", bodies.error().message.c_str());
      return 2;
    }
    // The networks of this scene: as the demo ships it, every interactor sequential (20
    // objects), and the baseline build's.
    struct Variant {
      const char* name;
      bool sequential;
      fs::path bin;
    };
    std::vector<Variant> variants{{"network", false, ctx.bin}};
    if (objects == 20) variants.push_back({"network-sequential", true, ctx.bin});
    if (!ctx.baseline.empty()) variants.push_back({"network-baseline", false, ctx.baseline});
    std::map<std::string, std::vector<double>> ratios, cpuRatios, medianRatios;
    for (int round = 0; round < rounds; ++round) {
      Monolithic mono;
      if (auto ok = mono.init(*bodies, objects == 20); !ok) {
        std::fprintf(stderr, "vrflow-bench-scene: %s\n", ok.error().message.c_str());
        return 2;
      }
      const Rate monoRate = loopRate([&] { mono.step(); }, warm, measured);
      char extra[320];
      std::snprintf(extra, sizeof extra,
                    ",\"cpu_ms_per_iteration\":%.3f,\"median_iteration_us\":%.1f,\"round\":%d,"
                    "\"load_average\":%.1f",
                    monoRate.cpuMsPerIteration, monoRate.medianIterationUs, round, loadAverage());
      print("monolithic", objects, monoRate.perSecond, extra);
      if (objects == 20) {
        // Before issue 26's stable net, in the same round: the springs once per step.
        Monolithic before;
        if (auto ok = before.init(*bodies, true, true); !ok) {
          std::fprintf(stderr, "vrflow-bench-scene: %s\n", ok.error().message.c_str());
          return 2;
        }
        const Rate beforeRate = loopRate([&] { before.step(); }, warm, measured);
        std::snprintf(extra, sizeof extra,
                      ",\"cpu_ms_per_iteration\":%.3f,\"of_monolithic\":%.3f,\"round\":%d,"
                      "\"load_average\":%.1f",
                      beforeRate.cpuMsPerIteration, beforeRate.perSecond / monoRate.perSecond,
                      round, loadAverage());
        print("monolithic-springs-once-a-step", objects, beforeRate.perSecond, extra);
      }
      for (const auto& variant : variants) {
        auto network = networkRate(ctx, variant.bin, objects, variant.sequential, warm, measured);
        if (!network) {
          std::fprintf(stderr, "vrflow-bench-scene: %s, %d objects: %s\n", variant.name, objects,
                       network.error().message.c_str());
          ++failures;
          continue;
        }
        const double ratio = network->perSecond / monoRate.perSecond;
        const double cpuRatio = network->cpuMsPerIteration / monoRate.cpuMsPerIteration;
        const double medianRatio = network->medianIterationUs > 0
                                       ? monoRate.medianIterationUs / network->medianIterationUs
                                       : 0;
        ratios[variant.name].push_back(ratio);
        cpuRatios[variant.name].push_back(cpuRatio);
        medianRatios[variant.name].push_back(medianRatio);
        std::snprintf(extra, sizeof extra,
                      ",\"of_monolithic\":%.3f,\"cpu_ms_per_iteration\":%.3f,"
                      "\"cpu_of_monolithic\":%.3f,\"median_iteration_us\":%.1f,"
                      "\"median_of_monolithic\":%.3f,\"round\":%d,\"load_average\":%.1f",
                      ratio, network->cpuMsPerIteration, cpuRatio, network->medianIterationUs,
                      medianRatio, round, loadAverage());
        print(variant.name, objects, network->perSecond, extra);
      }
    }
    for (const auto& [name, values] : ratios) {
      std::printf(
          "{\"variant\":\"%s\",\"objects\":%d,\"rounds\":%zu,"
          "\"of_monolithic_median\":%.3f,\"cpu_of_monolithic_median\":%.3f,"
          "\"median_of_monolithic_median\":%.3f}\n",
          name.c_str(), objects, values.size(), median(values), median(cpuRatios[name]),
          median(medianRatios[name]));
    }
    BulletWorld bullet;
    for (const rigid::Body& b : *bodies) bullet.add(b);
    print("bullet-world", objects, loopRate([&] { bullet.step(); }, warm, measured).perSecond,
          objects == 20 ? ",\"note\":\"rigid bodies only\"" : "");
  }
  std::error_code ignored;
  fs::remove_all(ctx.work, ignored);
  return failures == 0 ? 0 : 1;
}
