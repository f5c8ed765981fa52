"""Whether a process on this machine rests: every thread of it blocked, none put on a CPU between
two looks (Linux's /proc), the rule the simulator's lock-step reads a controller by (ProcessThreads,
src/ros/process_activity.h). A thread that spins, however small its share of a busy machine's
CPUs, is never seen so; a test waits for a process to rest instead of measuring its CPU time."""
import os

from onedof_sim.benchmark.lockstep_speed import thread_times


def thread_states(pid):
    """Each thread's state letter (R, S, D, ...) by thread id; empty when the process is gone."""
    states = {}
    try:
        tids = os.listdir('/proc/%d/task' % pid)
    except OSError:
        return states
    for tid in tids:
        try:
            with open('/proc/%d/task/%s/stat' % (pid, tid)) as f:
                # The state follows the command name, which is in parentheses and may hold spaces.
                states[tid] = f.read().rsplit(')', 1)[1].split()[0]
        except (OSError, IndexError):
            continue  # a thread gone meanwhile
    return states


def rests(pid):
    """Whether every thread of process pid is blocked (S) at two looks and none ran between them."""
    runs = thread_times(pid)
    if not runs:
        return False
    for _ in range(2):
        states = thread_states(pid)
        if set(states) != set(runs) or set(states.values()) != {'S'}:
            return False
    return thread_times(pid) == runs
