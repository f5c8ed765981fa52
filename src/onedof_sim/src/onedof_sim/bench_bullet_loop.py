"""The physics limit of the pybullet node: BulletWorld.step in a tight loop without ROS, run by the
benchmark under the pybullet node's own interpreter. The same protocol as bench_ode_loop:

  python -m onedof_sim.bench_bullet_loop (--urdf|--sdf NAME FILE X)...
then on stdin one window per line, "SECONDS MIN_STEPS"; for each it steps for at least both and
prints "window STEPS WALL_SECONDS SIM_SECONDS". It prints "ready" once the models are spawned.
"""
import sys
import time

from onedof_sim import bullet_world as bw


def run_window(world, seconds, min_steps):
    steps = 0
    start = time.perf_counter()
    until = start + seconds
    while True:
        world.step()
        steps += 1
        now = time.perf_counter()
        if now >= until and steps >= min_steps:
            return steps, now - start


def main(argv):
    if len(argv) % 4 or not argv:
        sys.exit('usage: python -m onedof_sim.bench_bullet_loop (--urdf|--sdf NAME FILE X)...')
    world = bw.BulletWorld()
    for i in range(0, len(argv), 4):
        flag, name, path, x = argv[i:i + 4]
        with open(path) as f:
            xml = f.read()
        status = world.spawn(name, xml, bw.ModelFormat(flag.lstrip('-')),
                             bw.Pose(bw.Vec3(float(x), 0.0, 0.0)))
        if not status.ok:
            sys.exit('bench_bullet_loop: spawn %s: %s' % (name, status.message))
    print('ready', flush=True)
    for line in sys.stdin:
        seconds, min_steps = line.split()
        steps, wall = run_window(world, float(seconds), int(min_steps))
        print('window', steps, wall, world.time(), flush=True)
    world.close()


if __name__ == '__main__':
    main(sys.argv[1:])
