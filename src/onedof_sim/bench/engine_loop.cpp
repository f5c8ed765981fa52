// bench_engine_loop: the physics limit of the node on one engine, World::step in a tight loop
// without ROS.
//
// What one step here includes is what the node's step includes minus ROS: effort jobs, collision
// detection, contacts and the engine's step (World::step). Missing are the world mutex, /clock and
// the pacing. The world is built once and keeps its state between measurement windows, as the
// node's does, so the two are compared on the same motion.
//
//   bench_engine_loop [--physics NAME] [--quick-step] --urdf NAME FILE X [--sdf NAME FILE X]...
// then on stdin, one window per line: "SECONDS MIN_STEPS"; for each it steps for at least both and
// prints "window STEPS WALL_SECONDS SIM_SECONDS". It prints "ready" once the models are spawned.
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>

#include <onedof_sim/world.h>

namespace {

int usage(const std::string& why) {
  std::cerr << "bench_engine_loop: " << why
            << "\nusage: bench_engine_loop [--physics NAME] [--quick-step] "
               "(--urdf|--sdf NAME FILE X)...; then lines SECONDS MIN_STEPS"
            << std::endl;
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  std::string engine = onedof_sim::World::engineNames().front();
  onedof_sim::PhysicsParams params;
  int i = 1;
  for (; i < argc; ++i) {
    const std::string option = argv[i];
    if (option == "--physics" && i + 1 < argc) {
      engine = argv[++i];
    } else if (option == "--quick-step") {
      // ODE's dWorldQuickStep (the node's ~quick_step) instead of the default dWorldStep.
      params.quick_step = true;
    } else {
      break;
    }
  }
  std::unique_ptr<onedof_sim::World> world;
  try {
    world = std::make_unique<onedof_sim::World>(engine, params);
  } catch (const std::invalid_argument& error) {
    return usage(error.what());
  }
  for (; i < argc; i += 4) {
    const std::string flag = argv[i];
    if ((flag != "--urdf" && flag != "--sdf") || i + 3 >= argc) return usage("bad arguments");
    std::ifstream file(argv[i + 2]);
    if (!file) return usage(std::string("cannot read ") + argv[i + 2]);
    std::stringstream xml;
    xml << file.rdbuf();
    onedof_sim::Pose pose;
    pose.position.x = std::atof(argv[i + 3]);
    const auto format = flag == "--urdf" ? onedof_sim::ModelFormat::Urdf
                                         : onedof_sim::ModelFormat::Sdf;
    const onedof_sim::Status status = world->spawn(argv[i + 1], xml.str(), format, pose);
    if (!status.ok()) {
      std::ostringstream why;
      why << "spawn " << argv[i + 1] << ": " << status;
      return usage(why.str());
    }
  }
  std::cout << "ready" << std::endl;

  using Clock = std::chrono::steady_clock;
  double seconds = 0;
  long min_steps = 0;
  while (std::cin >> seconds >> min_steps) {
    const auto start = Clock::now();
    const auto until = start + std::chrono::duration_cast<Clock::duration>(
                                   std::chrono::duration<double>(seconds));
    long steps = 0;
    // Reading the clock costs under 1 % of the smallest step.
    do {
      world->step();
      ++steps;
    } while (Clock::now() < until || steps < min_steps);
    const double wall = std::chrono::duration<double>(Clock::now() - start).count();
    std::cout << "window " << steps << " " << wall << " " << world->time() << std::endl;
  }
  return 0;
}
