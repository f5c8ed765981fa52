"""Item 9, the busy machine: the tutorial's first phase (play_tutorial --phases 1) with CPU-bound
processes beside it, lock-stepped and free-running at real-time factor 1, each against the
lock-stepped run on the quiet machine: lock-step keeps the figure, free-running loses periods."""
import json
import os
import subprocess

from onedof_harness.busy import busy_processes
from onedof_sim.benchmark.graph import NotMeasured, by_path
from onedof_sim.benchmark.lockstep_speed import COMMAND
from onedof_sim.tutorial import phases


def measure(bench, engine):
    duration = bench.sizes.comparison_phase_s
    busy = bench.sizes.busy_processes
    runs = {}
    try:
        quiet = first_phase(bench, engine, 'quiet_lockstep')
        for key, args in (('lockstep', ()), ('free_run', ('--free-run',))):
            with busy_processes(busy):
                runs[key] = first_phase(bench, engine, 'busy_' + key, *args)
    except (NotMeasured, subprocess.TimeoutExpired) as error:
        bench.not_measured('9', 'the tutorial\'s settled angle with %d busy processes beside '
                           'it, lock-stepped and free-running (node with _physics:=%s)'
                           % (busy, engine), str(error)[:300])
        return
    periods = round(duration / phases.CONTROL_PERIOD)
    against = ('the same, lock-stepped on the quiet machine (%d of %d samples)'
               % (quiet['samples'], periods))
    for key, title in (('lockstep', 'lock-stepped'),
                       ('free_run', 'free-running at real-time factor 1')):
        run = runs[key]
        bench.add('9', 'the tutorial\'s settled angle for command %g (its first phase, %g s of '
                  'sim time), %s, %d busy processes beside it (node with _physics:=%s; '
                  'controller samples: %d of %d)' % (
                      COMMAND, duration, title, busy, engine,
                      run['samples'], periods),
                  '%.6f rad (%+.1e from quiet)' % (run['settled'],
                                                    run['settled'] - quiet['settled']),
                  against, '%.6f rad' % quiet['settled'])
    bench.results['busy_machine'] = dict(quiet_lockstep=quiet, **runs)


def first_phase(bench, engine, name, *args):
    """Summary row of the tutorial's first phase played by play_tutorial (the main job)."""
    output = os.path.join(bench.work, name)
    env = dict(os.environ)
    env.pop('DISPLAY', None)
    result = subprocess.run(by_path(['rosrun', 'onedof_sim', 'play_tutorial', '--output', output,
                                     '--physics', engine, '--phases', '1', '--no-screenshot',
                                     '--no-figures',
                                     '--phase-duration', '%g' % bench.sizes.comparison_phase_s,
                                     '--in-sim-phase-duration', '0'] + list(args)),
                            capture_output=True, text=True, timeout=600, env=env)
    if result.returncode != 0:
        raise NotMeasured('play_tutorial %s: %s' % (' '.join(args), (result.stdout
                                                                     + result.stderr)[-300:]))
    with open(os.path.join(output, 'summary.json')) as f:
        return json.load(f)['phases'][0]
