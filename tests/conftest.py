"""Fixtures for the end-to-end tests: a private roscore per test, the simulator, a rospy client,
and a simulator shared by a module's tests (shared_sim).

Run under pytest-forked (the Makefile passes --forked): each test runs in its own process, so it can
init its own rospy node against its own roscore. Logs of every process a test started are printed
when the test fails.

Starting a roscore and a simulator takes seconds (many on a busy machine) where most API tests take
a fraction of one, so tests that ask for shared_sim run against one roscore and simulator per
module and engine, reset to a known world before each test (see SharedGraphs). A test that checks
start-up itself still starts its own node on its own roscore (the ros and sim fixtures).
"""
import os
import pickle
import shutil
import signal
import sys
import tempfile

import pytest

from onedof_harness import private_ros
from onedof_harness.private_ros import PrivateRos, wait_until
from onedof_sim.engines import engine_names
from onedof_sim.tools import package_executable

WORKSPACE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
TUTORIAL_URDF = os.path.join(WORKSPACE, 'src', 'minimal_robot_description',
                             'minimal_robot_description.urdf')
# The node lists its engines. The end-to-end tests run on the engines ONEDOF_TEST_ENGINES names
# (comma-separated, default ode and bullet, Gazebo classic's pair the suite has always measured;
# `all` for every engine): each engine adds hundreds of end-to-end cases, while the engine-level
# gtests (TEST_P over the registry) run every engine in every run.
ALL_ENGINES = engine_names()
_TEST_ENGINES = os.environ.get('ONEDOF_TEST_ENGINES', 'ode,bullet')
ENGINES = ALL_ENGINES if _TEST_ENGINES == 'all' else tuple(
    name for name in ALL_ENGINES if name in _TEST_ENGINES.split(','))
if not ENGINES:
    raise RuntimeError('ONEDOF_TEST_ENGINES=%s names none of the engines %s' % (
        _TEST_ENGINES, ', '.join(ALL_ENGINES)))
# The bound of each test in a file whose first test builds an overlay with catkin_make (the others
# wait for that build): the build's bound and as long again, past the suite's per-test bound,
# which a build on a busy machine exceeds.
OVERLAY_TESTS_TIMEOUT = pytest.mark.timeout(2 * private_ros.BUILD_TIMEOUT)
# The model a node started without a world file places, as gzserver's worlds/empty.world does:
# the world's ground.
GROUND = 'ground_plane'
GROUND_SDF = os.path.join(WORKSPACE, 'src', 'onedof_sim', 'models', 'ground_plane', 'model.sdf')


def ground_plane_sdf():
    with open(GROUND_SDF) as f:
        return f.read()


def pytest_configure(config):
    # Started in the background by a non-interactive shell, the suite inherits SIGINT ignored and
    # so would every node it starts: Ctrl-C (SIGINT) would not stop them, as it does in a
    # user's terminal. A handler is reset to the default in the programs this process starts.
    if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:
        signal.signal(signal.SIGINT, signal.default_int_handler)
    # Each test is a fork of this process: what every roscore needs is looked up once here,
    # and the modules the tests' ROS clients use are imported once here.
    private_ros.core_parameters()
    private_ros.rosout_command()
    simulator_executable()
    import rospy  # noqa: F401
    import gazebo_msgs.msg, gazebo_msgs.srv, geometry_msgs.msg, sensor_msgs.msg  # noqa: F401
    import std_msgs.msg, std_srvs.srv, rosgraph_msgs.msg  # noqa: F401


# The modules whose tests take tens of seconds each. They are handed to the workers first, so
# that the suite does not end on one of them running alone while the other workers idle.
LONG_MODULES = ('test_benchmark_cli', 'test_tutorial', 'test_tutorial_commands',
                'test_book_cpp_client', 'test_tutorial_rviz_failure', 'test_book_overlay',
                'test_book_tools', 'test_controller_manager_tools', 'test_rviz_sensors')


def pytest_collection_modifyitems(session, config, items):
    items.sort(key=lambda item: getattr(item.module, '__name__', '') not in LONG_MODULES)


@pytest.hookimpl(tryfirst=True, hookwrapper=True)
def pytest_runtest_makereport(item, call):
    outcome = yield
    report = outcome.get_result()
    setattr(item, 'report_' + report.when, report)


def uses_shared_sim(item):
    return 'shared_sim' in getattr(item, 'fixturenames', ())


def shared_key(item):
    return item.module.__name__, item.callspec.params['engine']


class SharedGraphs:
    """The roscores and simulators shared by a module's tests, one per (module, engine).

    pytest-forked runs a test's fixtures in the forked child and tears them all down there, module
    scope included, so a module-scoped fixture would still start a simulator per test. These graphs
    are started in the pytest (xdist worker) process before it forks a test that uses shared_sim,
    and stopped when that process moves on to another module or ends. The test's child attaches to
    its graph (view: a PrivateRos on the same roscore owning none of its processes), so it stops
    only what it started itself, and it must not poll the simulator (not its child). A graph whose
    test failed is replaced, so one failure never leaves a strange world to the next test."""

    def __init__(self):
        self._graphs = {}  # key -> (PrivateRos, simulator process) or the exception starting it

    def ensure(self, item):
        key = shared_key(item)
        entry = self._graphs.get(key)
        if isinstance(entry, tuple) and entry[1].poll() is None:
            return
        self.stop(key)
        graph = PrivateRos(log_dir=tempfile.mkdtemp(prefix='onedof_shared_%s_' % key[1]))
        try:
            graph.start_master()
            # A module may give its simulator more environment: shared_sim_env(graph env).
            env_of = getattr(item.module, 'shared_sim_env', None)
            proc = start_sim(graph, key[1], ['-u'], env=env_of(graph.env) if env_of else None)
            graph.params_at_start = graph.master().getParam('/conftest', '/')[2]
            self._graphs[key] = graph, proc
        except Exception as failure:  # reported by the test that needs it, not the worker
            graph.stop()
            self._graphs[key] = failure

    def view(self, item):
        entry = self._graphs.get(shared_key(item))
        if entry is None:
            pytest.fail('no shared simulator: the pytest process starts it before each test')
        if isinstance(entry, Exception):
            raise entry
        graph = entry[0]
        view = PrivateRos(log_dir=graph.log_dir)
        view.port, view.env, view.params_at_start = graph.port, graph.env, graph.params_at_start
        return view

    def stop(self, key):
        entry = self._graphs.pop(key, None)
        if isinstance(entry, tuple):
            entry[0].stop()
            shutil.rmtree(entry[0].log_dir, ignore_errors=True)

    def stop_all(self, unless_module=None):
        for key in list(self._graphs):
            if key[0] != unless_module:
                self.stop(key)


SHARED = SharedGraphs()
FAILED_TESTS = set()


@pytest.hookimpl(hookwrapper=True, tryfirst=True)
def pytest_runtest_protocol(item, nextitem):
    # Runs in the pytest process, before pytest-forked forks the test.
    if uses_shared_sim(item):
        SHARED.ensure(item)
    yield
    if uses_shared_sim(item) and item.nodeid in FAILED_TESTS:
        SHARED.stop(shared_key(item))
    SHARED.stop_all(unless_module=getattr(getattr(nextitem, 'module', None), '__name__', None))


def pytest_runtest_logreport(report):
    if report.failed:
        FAILED_TESTS.add(report.nodeid)


def pytest_sessionfinish(session):
    SHARED.stop_all()


def running_graph(request, graph, start=True):
    """Yields graph, its roscore started first unless it is attached to a running one; at the end
    stops every process the test started through it, and prints their logs if the test failed.
    For fixtures: `yield from running_graph(...)`."""
    if start:
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
    """This test's ROS graph: the module's shared one (attached, not owned) when the test uses
    shared_sim, else a private roscore on a free port. Stops every process the test started."""
    if uses_shared_sim(request.node):
        yield from running_graph(request, SHARED.view(request.node), start=False)
    else:
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
    """rospy initialised as a node of the private graph (one per forked test process). It is not
    shut down: the forked process ends with the test, and the graph's roscore is stopped after
    it; rospy's orderly shutdown would wait 0.5 s for its XML-RPC server's poll loop, in every
    test."""
    return init_rospy(ros)


def session_folder(tmp_path_factory, name):
    """A folder shared by this pytest session's workers (what one test builds or plays, the
    others read): under xdist each worker's temporary root is a folder of the session's own; run
    without xdist, the root is the session's, and its parent is every earlier session's."""
    base = tmp_path_factory.getbasetemp()
    if os.environ.get('PYTEST_XDIST_WORKER'):
        base = base.parent
    return base / name


def simulator_executable():
    """The simulator node's executable, found as rosrun and roslaunch find it. The tests start it
    by its path: rosrun's own lookup (a catkin_find process) costs each start 0.2 CPU-s. It runs
    through rosrun as a user types it in test_gazebo_ros.py's database request and the tutorial
    page's commands."""
    return package_executable('onedof_sim', 'onedof_sim')


# The simulator's two names beyond gazebo_ros' API, which the tests drive it and see it with.
EXTRAS = ['_enable_step_simulation:=true', '_enable_collision_markers:=true']


def start_sim(ros, engine=ENGINES[0], args=(), wait=True, env=None, extras=True):
    """Starts the simulator node of `engine` (with `env` added to the graph's environment) and
    waits until it serves its last service. With extras it serves /gazebo/step_simulation and
    publishes /gazebo/collision_markers; without, exactly gazebo_ros' names (as by default)."""
    proc = ros.start([simulator_executable(), '_physics:=' + engine] +
                     (EXTRAS if extras else []) + list(args), name='sim_' + engine, env=env)
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


@pytest.fixture
def shared_sim(ros, rospy_client, engine):
    """The module's simulator of each engine, reset to what a fresh `-u` node has: paused at sim
    time 0, the ground plane its only model, the start-up physics and parameters. Returns a
    GazeboApi on it."""
    from api_client import GazeboApi, pose
    api = GazeboApi(rospy_client)
    api.pause_physics()
    names = api.get_world_properties().model_names
    for name in names:
        if name != GROUND:
            res = api.delete_model(name)
            assert res.success, res.status_message
    if GROUND not in names:  # a test deleted it
        res = api.spawn_sdf_model(GROUND, ground_plane_sdf(), '', pose(), '')
        assert res.success, res.status_message
    api.reset_simulation()
    # The first test on a fresh simulator records its start-up physics for the others.
    start_up = os.path.join(ros.log_dir, 'start_up_physics.pickle')
    if os.path.exists(start_up):
        with open(start_up, 'rb') as f:
            physics = pickle.load(f)
        res = api.set_physics_properties(physics.time_step, physics.max_update_rate,
                                         physics.gravity, physics.ode_config)
        assert res.success, res.status_message
    else:
        with open(start_up, 'wb') as f:
            pickle.dump(api.get_physics_properties(), f)
    ros.master().setParam('/conftest', '/', ros.params_at_start)
    world = api.get_world_properties()
    assert (world.sim_time, world.model_names) == (0.0, [GROUND]), world
    yield api
    # Paused until the next test resets it: a world left running (some tests run it flat out)
    # would take a core from the tests beside it meanwhile.
    import rospy
    try:
        api.pause_physics()
    except (rospy.ServiceException, rospy.ROSException):
        pass  # a simulator the test stopped: the test says so, and the next one starts another


@pytest.fixture
def running_sim(shared_sim):
    """The module's simulator of each engine, running from sim time 0 as a fresh node does."""
    shared_sim.unpause_physics()
    return shared_sim
