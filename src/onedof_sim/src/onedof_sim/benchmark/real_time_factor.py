"""Item 5, real-time factor: how closely the simulator node paced at real-time factor 1 keeps to
the wall clock, from (CLOCK_MONOTONIC, sim time) /clock arrivals: the mean and the worst
one-second window. On the default engine it is measured during item 4's 100 Hz control run, on
the others with no controller."""
import os

from onedof_harness.private_ros import wait_until
from onedof_sim.benchmark import controller_periods
from onedof_sim.benchmark import report as bm
from onedof_sim.benchmark.graph import PROFILE_S, NotMeasured, node_label
from onedof_sim.benchmark.plots import write_pacing_plot


def measure(bench, engine, pacing_s, control=True):
    """Items 4 and 5 on one simulator of `engine` (item 5 alone without control)."""
    name = node_label(engine)
    sim = None
    try:
        sim, sim_pid = bench.start_sim(engine)
        bench.spawn(bench.tutorial_models[:1])
        if control:
            # The control run is paced at real-time factor 1 too: its /clock arrivals are the
            # pacing measurement, with the tutorial's controller running.
            clock = controller_periods.measure(bench, name)
            of_clock(bench, engine, sim_pid, clock, 'during the 100 Hz control run')
        else:
            without_controller(bench, engine, sim_pid, pacing_s)
    except (NotMeasured, TimeoutError) as error:
        bench.not_measured('4, 5' if control else '5', 'control loop and pacing, %s' % name,
                           str(error)[:200])
    finally:
        if sim:
            bench.stop(sim)


def without_controller(bench, engine, sim_pid, duration):
    probe = bench.clock_probe()
    try:
        wait_until(lambda: probe.samples, 30, what='/clock')
        end = probe.latest + duration
        wait_until(lambda: probe.latest >= end, duration * 5 + 30, interval=0.1,
                   what='%.0f s of sim time' % duration)
    finally:
        probe.close()
    of_clock(bench, engine, sim_pid, probe.samples, 'no controller')


def of_clock(bench, engine, sim_pid, clock, condition):
    """The real-time factor from (CLOCK_MONOTONIC, sim time) /clock arrivals."""
    name = node_label(engine)
    wall, sim = zip(*clock)
    duration = sim[-1] - sim[0]
    windows = bm.windowed_rtf(wall, sim, 1.0)
    mean = bm.mean_rtf(wall, sim)
    worst = max(windows, key=lambda f: abs(f - 1.0)) if windows else mean
    against = 'the wall clock (CLOCK_MONOTONIC at /clock arrival)'
    bench.add('5', 'real-time factor at 1.0, mean over %.0f s of sim time (%s, %s)'
              % (duration, name, condition), '%.4f' % mean, against, '1.0', mean,
              'within 1 %', abs(mean - 1) <= 0.01)
    bench.add('5', 'real-time factor, worst one-second window of %d (%s)'
              % (len(windows), name), '%.4f' % worst, against, '1.0', worst, 'within 1 %',
              abs(worst - 1) <= 0.01)
    bench.results.setdefault('pacing', {})[engine] = dict(mean=mean, windows=windows)
    if abs(mean - 1) > 0.01 or abs(worst - 1) > 0.01:
        bench.profile(sim_pid, PROFILE_S, '5_%s_node_paced' % engine)
    write_pacing_plot(windows, name, os.path.join(bench.output, 'pacing_%s.png' % engine))
