"""The simulator node as a process: its log lines reach a file as they are written, and SIGINT
stops it with nothing of it spinning meanwhile. Each test starts its own roscore and simulator."""
import os
import signal

from conftest import start_sim
from onedof_harness.process_rest import rests, thread_states
from onedof_harness.private_ros import wait_until

# Far longer than any of these waits takes, on any machine: only a bound on a hang.
HANG_SECONDS = 300


def test_the_log_reaches_a_file_line_by_line_while_the_node_runs(ros, engine):
    # rosconsole's own switch off: the node's stdout into a file, as `rosrun ... > log` gives it.
    sim = start_sim(ros, engine, env={'ROSCONSOLE_STDOUT_LINE_BUFFERED': '0'})
    ros.wait_until(lambda: '[ INFO]' in ros.log_text(sim) and
                   'serving the Gazebo API under /gazebo' in ros.log_text(sim), HANG_SECONDS,
                   what='the start-up INFO line in the log file of the running node')
    assert sim.poll() is None


def test_sigint_stops_the_node_and_nothing_spins_while_it_shuts_down(ros, engine):
    """roscpp's shutdown unregisters every service and topic with the master. With the master
    stopped (SIGSTOP), the node holds in that shutdown: its serving threads have ended (so it is
    shutting down), and every thread left must rest there (a spinning one, such as a spinner
    polling the disabled callback queue, never does). Then the master goes on and the node exits 0."""
    sim = start_sim(ros, engine)
    threads_running = len(thread_states(sim.pid))
    os.kill(ros.roscore.pid, signal.SIGSTOP)
    try:
        sim.send_signal(signal.SIGINT)
        wait_until(lambda: len(thread_states(sim.pid)) < threads_running and rests(sim.pid),
                   HANG_SECONDS, what='the node, shutting down (its serving threads ended), to '
                   'rest while the master is stopped')
    finally:
        os.kill(ros.roscore.pid, signal.SIGCONT)
    assert sim.wait(timeout=HANG_SECONDS) == 0, ros.log_text(sim)
