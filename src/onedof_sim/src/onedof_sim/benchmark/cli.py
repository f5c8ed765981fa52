"""rosrun onedof_sim benchmark: measures the simulator node on every engine side by side with its
references on one private ROS graph, and writes the table (README-table.md), the plots and
results.json.

The items, by their row of the table, short ones first so that a failure shows early:
  6 start-up, 1 loop speed + 7 memory, 2 scaling, 3 service round trips, 4 controller periods +
  5 real-time factor, 8 the real-time factor of the lock-stepped tutorial with each controller
  against its floor, and step_simulation with only in-simulator controllers against the free
  loop, 9 the tutorial's settled angle on a busy machine, lock-step against free-running, 10 a
  camera's cost, 11 the laser's cost on the book's mobot in its pen, 12 the Gazebo window's cost;
  each in a module of its own (startup, loop_speed, memory, scaling, round_trips,
  controller_periods, real_time_factor, lockstep_speed, in_sim_stepping, busy_machine,
  camera_cost, laser_cost, window_cost).
What is compared runs alternately in short windows (never at the same time: two cores), and the
ratio of the two is the claim. Nothing here fails on speed; a node that cannot be measured (not
built, crashed) gets its rows marked as not measured and the run goes on, and a missing profiler
is said so in the notes.
"""
import argparse
import dataclasses
import datetime
import json
import os
import shutil
import sys
import time
import traceback

from onedof_harness.private_ros import PrivateRos
from onedof_sim.benchmark import (busy_machine, camera_cost, in_sim_stepping, laser_cost,
                                  lockstep_speed, loop_speed, real_time_factor, round_trips,
                                  scaling, startup, window_cost)
from onedof_sim.benchmark import report as bm
from onedof_sim.benchmark.graph import Bench, read_file, say
from onedof_sim.engines import default_engine, engine_names


@dataclasses.dataclass
class Sizes:
    startup_repeats: int = 3
    throughput_windows: int = 5
    throughput_window_s: float = 1.0
    memory_steps: int = 1000000
    chain_links: tuple = (1, 10, 50, 200)
    chain_windows: int = 2
    chain_window_s: float = 1.0
    chain_min_steps: int = 3
    latency_batches: int = 3
    persistent_calls: int = 300
    fresh_calls: int = 50
    control_s: float = 60.0
    sweep_rates: tuple = (200, 500, 1000)
    sweep_s: float = 10.0
    # The default engine's pacing is measured during its control_s control run; the other
    # engines' (no control run) over pacing_s.
    pacing_s: float = 10.0
    # Sim seconds the lock-stepped tutorial is stepped through with each controller (item 8),
    # and the tutorial phase played for the comparison on a busy machine (item 9).
    lockstep_s: float = 10.0
    comparison_phase_s: float = 5.0
    # CPU-bound processes beside the busy-machine comparison (item 9): 8 as `make test-under-load`.
    busy_processes: int = 8
    # The camera's windows with and without it (item 10), and the renderer's bare frames.
    camera_windows: int = 5
    camera_window_s: float = 1.0
    render_frames: int = 200
    # The laser's cost (item 11): alternating windows with and without /scan subscribed, and the
    # sim seconds paced at real-time factor 1 with it.
    laser_windows: int = 5
    laser_window_s: float = 1.0
    laser_real_time_s: float = 10.0
    # The node's windows with no Gazebo window, with it open, and with none again (item 12).
    window_cost_windows: int = 3
    window_cost_window_s: float = 2.0


# The rows of the table, one per kind of measurement.
ROWS = (1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12)
FULL = Sizes()
# The smallest run that still measures every row against its reference: it shows that the
# benchmark works, and its figures are no claim. It starts no busy process beside item 9, whose
# runs still set lock-step against free-running on the machine as busy as it is (a spinner
# beside a quick run would only take a core from the tests running beside it).
QUICK = Sizes(startup_repeats=1, throughput_windows=1, throughput_window_s=0.1, memory_steps=20000,
              chain_links=(1, 10), chain_windows=1, chain_window_s=0.05, chain_min_steps=2,
              latency_batches=1, persistent_calls=20, fresh_calls=5, control_s=2.0,
              sweep_rates=(200,), sweep_s=0.5, pacing_s=2.0, lockstep_s=0.2,
              comparison_phase_s=0.5, busy_processes=0, camera_windows=1, camera_window_s=0.3,
              render_frames=20, laser_windows=1, laser_window_s=0.2, laser_real_time_s=1.0,
              window_cost_windows=1, window_cost_window_s=0.3)


def load_average():
    """The 1-minute load average: the run's figures mean little on a machine busy elsewhere."""
    return float(read_file('/proc/loadavg').split()[0])


def machine(load_at_start):
    return {'cpu': bm.cpu_model(read_file('/proc/cpuinfo')), 'cores': os.cpu_count(),
            'load': '%.1f / %.1f' % (load_at_start, load_average())}


def parse_args(argv):
    parser = argparse.ArgumentParser(
        prog='rosrun onedof_sim benchmark',
        description='Measures the simulator node on each engine side by side with bare '
                    'references on a private ROS graph; writes README-table.md, plots and '
                    'results.json.')
    parser.add_argument('--output', default='output/bench', help='output folder')
    parser.add_argument('--quick', action='store_true',
                        help='tiny sizes (seconds instead of minutes): checks that it runs')
    parser.add_argument('--engines',
                        help='comma-separated engines (default: every one the node lists)')
    parser.add_argument('--no-profiles', action='store_true',
                        help='never profile, also where an aim is missed (for tests, whose path '
                             'must not depend on how busy the machine is)')
    parser.add_argument('--book-client-overlay', metavar='FOLDER',
                        help='build the book-shaped C++ client (row 8) in FOLDER once and reuse '
                             'that build in later runs given the same FOLDER (default: a fresh '
                             'build in each run)')
    parser.add_argument('--items', default=','.join(str(row) for row in ROWS),
                        help='comma-separated row numbers to measure (default: all, %s)'
                             % ','.join(str(row) for row in ROWS))
    args = parser.parse_args(argv)
    try:
        args.items = {int(row) for row in args.items.split(',') if row}
    except ValueError:
        parser.error('--items takes row numbers: %s' % args.items)
    if not args.items or not args.items <= set(ROWS):
        parser.error('--items: rows are %s' % ','.join(str(row) for row in ROWS))
    try:
        known = engine_names()
    except RuntimeError as error:
        parser.error(str(error))
    args.engines = [e for e in args.engines.split(',') if e] if args.engines else list(known)
    unknown = [e for e in args.engines if e not in known]
    if unknown:
        parser.error('unknown engine(s): %s' % ', '.join(unknown))
    return args


def items(bench, engines, sizes):
    """(the table's row numbers an item measures, its title, the measurement) in the order they
    run."""
    found = [({6}, '6 start-up', lambda: startup.measure(bench))]
    found += [({1, 7}, '1, 7 throughput and memory, ' + e,
               lambda e=e: loop_speed.measure_with_memory(bench, e)) for e in engines]
    found += [({2}, '2 scaling', lambda: scaling.measure(bench))]
    found += [({3}, '3 latency, ' + e, lambda e=e: round_trips.measure(bench, e))
              for e in engines]
    # The controller's loop is measured on the default engine, the others' pacing alone.
    found += [({4, 5}, '4, 5 control loop and pacing, ' + e,
               lambda e=e: real_time_factor.measure(bench, e, sizes.pacing_s,
                                                    control=e == default_engine()))
              for e in engines]
    # Lock-step on the run's first engine (the default unless --engines says otherwise): the
    # controller sets the pace, not the engine.
    found += [({8}, '8 lock-step speed, ' + engines[0],
               lambda: lockstep_speed.measure(bench, engines[0])),
              ({8}, '8 stepping with in-simulator controllers, ' + engines[0],
               lambda: in_sim_stepping.measure(bench, engines[0])),
              ({9}, '9 busy machine, ' + engines[0],
               lambda: busy_machine.measure(bench, engines[0])),
              ({10}, '10 camera, ' + engines[0], lambda: camera_cost.measure(bench, engines[0]))]
    found += [({11}, '11 laser cost, ' + e, lambda e=e: laser_cost.measure(bench, e))
              for e in engines]
    found += [({12}, '12 window cost, ' + engines[0],
               lambda: window_cost.measure(bench, engines[0]))]
    return found


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    sizes = QUICK if args.quick else FULL
    output = os.path.abspath(args.output)
    os.makedirs(output, exist_ok=True)
    log_dir = os.path.join(output, 'logs')
    shutil.rmtree(log_dir, ignore_errors=True)
    engines = args.engines
    started = time.monotonic()
    load_at_start = load_average()
    date = datetime.datetime.now().astimezone().strftime('%Y-%m-%d %H:%M %Z')
    with PrivateRos(log_dir=log_dir) as ros:
        say('roscore on %s (logs in %s)' % (ros.master_uri, log_dir))
        bench = Bench(ros, sizes, output, engines, profiles=not args.no_profiles,
                      book_client_overlay=args.book_client_overlay)
        chosen = [(title, run) for rows, title, run in items(bench, engines, sizes)
                  if rows & args.items]
        try:
            for title, run in chosen:
                say('--- %s (%.0f s so far)' % (title, time.monotonic() - started))
                try:
                    run()
                except Exception:  # one broken item must not lose the others' figures
                    bench.notes.append('%s failed: %s' % (title, traceback.format_exc(limit=3)
                                                          .strip().splitlines()[-1]))
                    say(traceback.format_exc())
        finally:
            bench.close()
    elapsed = time.monotonic() - started
    bench.notes.insert(0, 'Run: `rosrun onedof_sim benchmark%s` in %.0f s of wall time; plots '
                       'next to this table; raw figures in results.json.'
                       % (' --quick' if args.quick else '', elapsed))
    host = machine(load_at_start)
    table = bm.render_table(bench.rows, host, date, bench.notes)
    with open(os.path.join(output, 'README-table.md'), 'w') as f:
        f.write(table)
    with open(os.path.join(output, 'results.json'), 'w') as f:
        json.dump(dict(machine=host, date=date, quick=args.quick, elapsed_s=elapsed,
                       results=bench.results), f, indent=1, default=str)
    print(table)
    say('done in %.0f s; outputs in %s' % (elapsed, output))
    return 0
