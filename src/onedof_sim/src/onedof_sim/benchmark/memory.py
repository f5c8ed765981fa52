"""Item 7, memory: the simulator node's memory after start and after a million more steps as fast as
possible, sampled along the way (/proc/PID/status). Measured on the node of item 1
(loop_speed), between its first steps and its windows."""
import time

from onedof_harness.private_ros import wait_until
from onedof_sim.benchmark.graph import CLOCK_FREQUENCY, STEP, node_label, read_file

# /clock at 100 Hz: publishing it every step costs a node more than its physics (item 1), and
# the steps, not the clock, are what is measured here.
MEMORY_CLOCK_FREQUENCY = 100.0


def memory_kb(pid):
    """{'VmRSS', 'RssAnon', 'RssFile'} of a process from /proc/PID/status, in kB: anonymous
    memory is what a leak grows; file-backed pages are code and data of the libraries, paged in
    on first use."""
    fields = {}
    for line in read_file('/proc/%d/status' % pid).splitlines():
        key, _, value = line.partition(':')
        if key in ('VmRSS', 'RssAnon', 'RssFile'):
            fields[key] = int(value.split()[0])
    return fields


def format_memory(fields):
    return '%.1f MiB (anonymous %.1f, file-backed %.1f)' % (
        fields['VmRSS'] / 1024, fields['RssAnon'] / 1024, fields['RssFile'] / 1024)


def measure(bench, engine, pid, sim_time):
    """Memory of the node after start, then after memory_steps more steps as fast as possible,
    sampled along the way: growth in the second half would be a leak, growth in the first half
    alone is warm-up. sim_time() gives (wall, sim) seconds of the paused node."""
    sizes = bench.sizes
    start, sim_start = memory_kb(pid), sim_time()[1]
    target = sim_start + sizes.memory_steps * STEP
    samples = []

    def done():
        sim = sim_time()[1]
        samples.append((sim - sim_start, memory_kb(pid)['RssAnon']))
        return sim >= target

    bench.ros.set_param(CLOCK_FREQUENCY, MEMORY_CLOCK_FREQUENCY)
    bench.pause(False)
    started = time.monotonic()
    wait_until(done, sizes.memory_steps / 1000.0 + 60, interval=0.2,
               what='%d steps' % sizes.memory_steps)
    bench.pause(True)
    bench.ros.set_param(CLOCK_FREQUENCY, 0.0)
    wall = time.monotonic() - started
    end = memory_kb(pid)
    half = sizes.memory_steps * STEP / 2
    at_half = next(anon for steps, anon in samples if steps >= half)
    growth = end['RssAnon'] / start['RssAnon'] - 1
    bench.add('7', 'memory (/proc/PID/status) of the %s after %d more steps (%.0f s as '
              'fast as possible, /clock at %d Hz); anonymous growth in the second half: '
              '%+.1f MiB' % (node_label(engine), sizes.memory_steps, wall,
                             MEMORY_CLOCK_FREQUENCY, (end['RssAnon'] - at_half) / 1024),
              format_memory(end), 'the same node after start (models spawned, 100 steps)',
              format_memory(start), end['RssAnon'] / start['RssAnon'],
              'flat: anonymous growth < 2 %', growth < 0.02)
    bench.results.setdefault('memory', {})[engine] = dict(start=start, end=end,
                                                          anon_by_steps=samples)
