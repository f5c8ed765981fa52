"""Bare pybullet, the reference of the Bullet node's throughput: the models loaded by pybullet's own
loaders with the cross-validation's settings (onedof_sim.reference.pybullet_reference), then
stepSimulation alone in a tight loop. The protocol of bench_engine_loop:

  python -m onedof_sim.benchmark.pybullet_loop (--urdf|--sdf NAME FILE X)...
then on stdin one window per line, "SECONDS MIN_STEPS"; for each it steps for at least both and
prints "window STEPS WALL_SECONDS SIM_SECONDS". It prints "ready" once the models are loaded.
(Under a python with pybullet: the workspace venv's.)
"""
import os
import sys
import time

from onedof_sim.reference.pybullet_reference import TIME_STEP, PybulletWorld

USAGE = 'usage: python -m onedof_sim.benchmark.pybullet_loop (--urdf|--sdf NAME FILE X)...'
# Steps between two readings of the clock: reading it every step would add a few % to a step.
BATCH = 100


def run_window(step, seconds, min_steps):
    """(steps, wall seconds) of stepping for at least `seconds` and `min_steps`, in batches."""
    steps = 0
    start = time.perf_counter()
    until = start + seconds
    while True:
        for _ in range(BATCH):
            step()
        steps += BATCH
        now = time.perf_counter()
        if now >= until and steps >= min_steps:
            return steps, now - start


def main(argv):
    if not argv or len(argv) % 4:
        sys.exit(USAGE)
    # pybullet's C code prints to file descriptor 1, in pieces without line ends: the protocol
    # gets a stream of its own and everything else goes to stderr.
    protocol = os.fdopen(os.dup(1), 'w')
    os.dup2(2, 1)
    world = PybulletWorld()
    for flag, _, path, x in zip(*[iter(argv)] * 4):
        if flag == '--urdf':
            world.load_urdf(path, float(x))
        elif flag == '--sdf':
            world.load_sdf(path, float(x))
        else:
            sys.exit(USAGE)
    print('ready', file=protocol, flush=True)
    steps = 0
    for line in sys.stdin:
        seconds, min_steps = line.split()
        window_steps, wall = run_window(world.client.stepSimulation, float(seconds),
                                        int(min_steps))
        steps += window_steps
        print('window', window_steps, wall, steps * TIME_STEP, file=protocol, flush=True)
    world.close()


if __name__ == '__main__':
    main(sys.argv[1:])
