"""A process that goes on after its rospy node is shut down stays idle: rospy's own shutdown
leaves its XML-RPC thread polling a closed socket, a core's worth of CPU (rospy_shutdown)."""
import subprocess
import sys
import textwrap

from onedof_harness.private_ros import PrivateRos, wait_until
from onedof_harness.process_rest import rests
from onedof_sim.benchmark.lockstep_speed import thread_times

# A node that shuts down ('ours' or rospy's own), says so, and idles until its stdin closes.
NODE = textwrap.dedent('''
    import sys
    import rospy
    from onedof_harness.rospy_shutdown import shut_down_rospy
    rospy.init_node('idle_after_shutdown', anonymous=True, disable_signals=True)
    if sys.argv[1] == 'ours':
        shut_down_rospy(rospy, 'done')
    else:
        rospy.signal_shutdown('done')
    print('shut down', flush=True)
    sys.stdin.read()
''')
# CPU time a polling thread takes in a fraction of a second of a core; an idle process none.
POLLING_CPU_NS = 200000000
# Only a bound on a hang: a polling thread on a machine busy with 20 other processes gets a
# small share of a core.
HANG_SECONDS = 300


def cpu_ns(pid):
    return sum(on_cpu for on_cpu, _ in thread_times(pid).values())


def after_shutdown(graph, how, condition, what):
    """Runs the node, shut down `how`; waits until condition(pid) holds after its shutdown."""
    node = subprocess.Popen([sys.executable, '-c', NODE, how], env=graph.env, text=True,
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE)
    try:
        assert node.stdout.readline() == 'shut down\n'
        wait_until(lambda: condition(node.pid), HANG_SECONDS, what=what)
    finally:
        node.stdin.close()
    assert node.wait(timeout=HANG_SECONDS) == 0


def test_a_node_shut_down_rests_where_rospys_own_shutdown_polls(tmp_path):
    graph = PrivateRos(log_dir=str(tmp_path))
    try:
        graph.start_master()
        # Every thread of it blocked and none run between two looks: a polling one never is.
        after_shutdown(graph, 'ours', rests, 'the node shut down by shut_down_rospy to rest')
        # The defect it works around, still there: otherwise this module has no reason to be.
        since_shutdown = {}

        def polled(pid):
            since_shutdown.setdefault(pid, cpu_ns(pid))
            return cpu_ns(pid) - since_shutdown[pid] > POLLING_CPU_NS
        after_shutdown(graph, 'rospy', polled, "rospy's own shutdown to leave a thread polling")
    finally:
        graph.stop()
