"""Fixtures for the end-to-end tests: a private roscore per test, the simulator, a rospy client.

Run under pytest-forked (the Makefile passes --forked): each test runs in its own process, so it can
init its own rospy node against its own roscore. Logs of every process a test started are printed
when the test fails.

A module whose tests only need a simulator in a known state takes `shared_sim` instead: one roscore
and simulator per engine for all of the module's tests that a worker runs in a row (started in the
worker before pytest-forked forks the test, so that it outlives each test); the module resets the
world between tests.
"""
import os
import sys

import pytest

from onedof_sim.engines import engine_names, node_command
from onedof_sim.private_ros import PrivateRos, wait_until

WORKSPACE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TUTORIAL_URDF = os.path.join(WORKSPACE, 'src', 'minimal_robot_description',
                             'minimal_robot_description.urdf')
# The node lists its engines; pytest parametrizes with them at collection.
ENGINES = engine_names()


@pytest.hookimpl(tryfirst=True, hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    setattr(item, 'report_' + report.when, report)


def running_graph(request, graph):
    """Starts graph's roscore and yields graph; at the end stops every process it started, and
    prints their logs if the test failed. For fixtures: `yield from running_graph(...)`."""
    graph.start_master()
    try:
        yield graph
    finally:
        failed = any(getattr(request.node, 'report_' + when, None) is not None
                     and getattr(request.node, 'report_' + when).failed
                     for when in ('setup', 'call'))
        graph.stop()
        if failed:
            for name in sorted(os.listdir(graph.log_dir)):
                if name.endswith('.log'):
                    text = graph.log_text(name[:-4])
                    sys.stderr.write('----- %s (last 3000 chars) -----\n%s\n' % (name, text[-3000:]))


@pytest.fixture
def ros(request, tmp_path):
    """A private roscore on a free port; stops every process it started."""
    yield from running_graph(request, PrivateRos(log_dir=str(tmp_path / 'ros')))


def init_rospy(graph):
    """rospy initialised as a node of `graph` (a PrivateRos), once per forked test process."""
    import rospy
    if rospy.core.is_initialized():
        pytest.fail('rospy is already initialised in this process: run pytest with --forked')
    graph.adopt_environment()
    rospy.init_node('test_client', anonymous=True, disable_signals=True)
    return rospy


@pytest.fixture
def rospy_client(ros):
    """rospy initialised as a node of the private graph (one per forked test process)."""
    rospy = init_rospy(ros)
    yield rospy
    rospy.signal_shutdown('test finished')


def start_sim(ros, engine=ENGINES[0], args=(), wait=True):
    """Starts the simulator node of `engine` and waits until it serves its last service."""
    proc = ros.start(node_command(engine) + list(args), name='sim_' + engine)
    if wait:
        wait_until(lambda: proc.poll() is not None or ros.has_service('/gazebo/unpause_physics'),
                   60, what='the %s simulator to serve /gazebo/unpause_physics' % engine)
        assert proc.poll() is None, 'simulator exited:\n' + ros.log_text(proc)
    return proc


@pytest.fixture(params=ENGINES)
def engine(request):
    return request.param


@pytest.fixture
def sim(ros, engine):
    """The simulator of each engine, running against the private roscore."""
    return start_sim(ros, engine)


# --- one simulator per engine shared by a module's tests --------------------------------------

# Started simulators by (module, engine), in this worker: {key: PrivateRos, or the start failure}.
_shared_sims = {}


def _shared_sim_key(item):
    if item is None or 'shared_sim' not in getattr(item, 'fixturenames', ()):
        return None
    return item.module.__name__, item.callspec.params['engine']


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    """Starts the shared simulator before the test is forked, and stops it once the worker's next
    test needs another one (or none)."""
    key = _shared_sim_key(item)
    if key is not None and key not in _shared_sims:
        graph = PrivateRos()
        try:
            graph.start_master()
            start_sim(graph, key[1], getattr(item.module, 'SHARED_SIM_ARGS', ()))
            _shared_sims[key] = graph
        except Exception as failure:  # reported by the test's set-up, in shared_sim
            graph.stop()
            _shared_sims[key] = failure
    yield
    if key is not None and _shared_sim_key(nextitem) != key:
        shared = _shared_sims.pop(key)
        if isinstance(shared, PrivateRos):
            shared.stop()


@pytest.fixture
def shared_sim(request, engine):
    """The module's simulator of `engine` (args: the module's SHARED_SIM_ARGS), a PrivateRos; its
    log is printed when the test fails."""
    shared = _shared_sims.get(_shared_sim_key(request.node))
    if not isinstance(shared, PrivateRos):
        pytest.fail('the shared %s simulator did not start: %s' % (engine, shared))
    yield shared
    call = getattr(request.node, 'report_call', None)
    if call is not None and call.failed:
        for proc in shared.processes:
            sys.stderr.write('----- %s (last 3000 chars) -----\n%s\n'
                             % (proc.log_name, shared.log_text(proc)[-3000:]))
