"""The private roscore never takes someone else's port for its own: the port it chose can be taken
between choosing and binding it. A wait notices at once when a process the graph started dies."""
import os
import socket
import subprocess
import sys
import threading
import xmlrpc.server

import pytest

from onedof_harness import private_ros
from onedof_harness.private_ros import PrivateRos, ProcessExited, free_port, is_descendant


def ports_taken_first(monkeypatch, taken):
    """free_port answers the ports in `taken` first, then free ones."""
    queue = list(taken)
    monkeypatch.setattr(private_ros, 'free_port', lambda: queue.pop(0) if queue else free_port())


def test_is_descendant_follows_the_parent_chain():
    assert is_descendant(os.getpid(), os.getppid())
    assert is_descendant(os.getpid(), os.getpid())
    assert not is_descendant(os.getppid(), os.getpid())


def test_a_port_answered_by_another_xmlrpc_server_is_left_for_another(monkeypatch, tmp_path):
    server = xmlrpc.server.SimpleXMLRPCServer(('127.0.0.1', 0), logRequests=False)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    ports_taken_first(monkeypatch, [server.server_address[1]])
    graph = PrivateRos(log_dir=str(tmp_path))
    try:
        graph.start_master()
        assert graph.port != server.server_address[1]
        code, _, pid = graph.master().getPid('/test')
        assert code == 1 and is_descendant(pid, graph.roscore.pid)
    finally:
        graph.stop()
        server.shutdown()


def test_a_port_answered_by_another_roscore_is_left_for_another(monkeypatch, tmp_path):
    with PrivateRos(log_dir=str(tmp_path / 'other')) as other:
        ports_taken_first(monkeypatch, [other.port])
        graph = PrivateRos(log_dir=str(tmp_path / 'ours'))
        try:
            graph.start_master()
            assert graph.port != other.port
            _, _, pid = graph.master().getPid('/test')
            assert is_descendant(pid, graph.roscore.pid)
            assert not is_descendant(pid, other.roscore.pid)
        finally:
            graph.stop()


def test_it_says_what_happened_when_no_port_works(monkeypatch, tmp_path):
    server = xmlrpc.server.SimpleXMLRPCServer(('127.0.0.1', 0), logRequests=False)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    port = server.server_address[1]
    monkeypatch.setattr(private_ros, 'free_port', lambda: port)
    graph = PrivateRos(log_dir=str(tmp_path))
    try:
        with pytest.raises(RuntimeError, match='answers for another program'):
            graph.start_master(attempts=2)
        assert not graph.processes
    finally:
        graph.stop()
        server.shutdown()


def bound_address(family, wildcard, address):
    """Where a child process with the graph's listening environment for `address` binds when it
    asks for the wildcard address."""
    script = ('import socket; s = socket.socket(socket.%s); s.bind((%r, 0)); '
              'print(s.getsockname()[0])' % (family, wildcard))
    env = dict(os.environ, **private_ros.listening_environment(address))
    return subprocess.run([sys.executable, '-c', script], env=env, capture_output=True,
                          text=True, check=True).stdout.strip()


def test_a_wildcard_bind_binds_the_graphs_address_instead():
    assert bound_address('AF_INET', '0.0.0.0', '127.0.0.1') == '127.0.0.1'
    assert bound_address('AF_INET6', '::', '127.0.0.1') == '::ffff:127.0.0.1'
    assert bound_address('AF_INET6', '::', '::1') == '::1'


def test_a_bind_to_a_named_address_is_left_alone():
    assert bound_address('AF_INET', '127.0.0.2', '127.0.0.1') == '127.0.0.2'


def test_a_port_held_by_a_program_that_never_answers_is_left_for_another(monkeypatch, tmp_path):
    """A listener that accepts connections (its backlog does) but never replies: waiting for its
    answer must not hang the roscore's start."""
    silent = socket.socket()
    silent.bind(('127.0.0.1', 0))
    silent.listen(16)
    ports_taken_first(monkeypatch, [silent.getsockname()[1]])
    graph = PrivateRos(log_dir=str(tmp_path))
    started = threading.Thread(target=graph.start_master, daemon=True)
    try:
        started.start()
        started.join(timeout=120)
        assert not started.is_alive(), 'start_master still waits for the silent port'
        assert graph.port != silent.getsockname()[1]
        _, _, pid = graph.master().getPid('/test')
        assert is_descendant(pid, graph.roscore.pid)
    finally:
        graph.stop()
        silent.close()

def test_a_wait_fails_at_once_naming_a_started_process_that_died_with_its_log_tail(tmp_path):
    graph = PrivateRos(log_dir=str(tmp_path))
    graph.env = dict(os.environ)  # no roscore: only start() and the wait are under test
    graph.start(['sh', '-c', 'sleep 60'], name='long_runner')
    graph.start(['sh', '-c', 'echo starting; echo "cannot resolve localhost" >&2; exit 3'],
                name='launch_simulator')
    try:
        # ProcessExited, not the TimeoutError of a wait that ran its course (600 s).
        with pytest.raises(ProcessExited) as failure:
            graph.wait_until(lambda: False, 600, what='service /gazebo/get_model_state')
    finally:
        graph.stop()
    message = str(failure.value)
    assert 'launch_simulator exited (status 3)' in message
    assert 'service /gazebo/get_model_state' in message
    assert message.endswith('starting\ncannot resolve localhost')
    assert 'long_runner' not in message


def test_a_wait_ignores_processes_that_may_exit_or_were_stopped(tmp_path):
    graph = PrivateRos(log_dir=str(tmp_path))
    graph.env = dict(os.environ)
    one_shot = graph.start(['true'], name='one_shot', may_exit=True)
    stopped = graph.start(['sleep', '60'], name='stopped')
    graph.terminate(stopped)
    try:
        one_shot.wait(timeout=30)
        assert graph.wait_until(lambda: 'done', 5) == 'done'
    finally:
        graph.stop()


def test_the_roscore_has_the_parameters_and_rosout_of_roscore(tmp_path):
    """What roscore.xml gives a roscore: the versions as `rosversion` prints them, a run id, and
    rosout aggregating the nodes' log lines."""
    with PrivateRos(log_dir=str(tmp_path)) as graph:
        master = graph.master()
        assert sorted(master.getParamNames('/test')[2]) == ['/rosdistro', '/rosversion',
                                                            '/run_id']
        for name, command in (('/rosversion', ['rosversion', 'roslaunch']),
                              ('/rosdistro', ['rosversion', '-d'])):
            assert master.getParam('/test', name)[2] == graph.run(command).stdout, name
        assert master.getParam('/test', '/run_id')[2]
        _, _, state = master.getSystemState('/test')
        publishers, subscribers, _ = state
        assert ['/rosout_agg', ['/rosout']] in publishers
        assert ['/rosout', ['/rosout']] in subscribers


def test_stop_leaves_no_process_of_the_graph(tmp_path):
    """Stopping the graph ends the roscore's master and rosout and every process started
    through it, with whatever they started in sessions of their own."""
    import psutil
    graph = PrivateRos(log_dir=str(tmp_path))
    graph.start_master()
    node = graph.start([sys.executable, '-c', 'import time; time.sleep(600)'], name='sleeper')
    code, _, master_pid = graph.master().getPid('/test')
    assert code == 1
    assert graph.master().lookupNode('/test', '/rosout')[0] == 1
    started = [psutil.Process(proc.pid) for proc in (graph.roscore, graph.rosout, node)]
    started += [child for proc in list(started) for child in proc.children(recursive=True)]
    assert master_pid in [p.pid for p in started]
    graph.stop()
    _, alive = psutil.wait_procs(started, timeout=60)
    assert not alive, alive


def test_restart_master_starts_an_empty_master_on_the_same_port_and_keeps_the_nodes(tmp_path):
    import psutil
    graph = PrivateRos(log_dir=str(tmp_path), use_sim_time=True)
    graph.start_master()
    try:
        node = graph.start([sys.executable, '-c', 'import time; time.sleep(600)'], name='sleeper')
        port, old_roscore = graph.port, graph.roscore
        _, _, old_pid = graph.master().getPid('/test')
        old_core = [psutil.Process(old_roscore.pid), psutil.Process(graph.rosout.pid)]
        assert graph.master().hasParam('/test', '/use_sim_time')[2]

        graph.restart_master()

        assert graph.port == port
        code, _, pid = graph.master().getPid('/test')
        assert code == 1 and pid != old_pid and is_descendant(pid, graph.roscore.pid)
        assert not graph.master().hasParam('/test', '/use_sim_time')[2]
        _, alive = psutil.wait_procs(old_core, timeout=60)
        assert not alive, alive
        assert node.poll() is None
        assert graph.processes.count(graph.roscore) == 1 and old_roscore not in graph.processes
        # A rosout of its own, as roscore starts it.
        assert graph.master().lookupNode('/test', '/rosout')[0] == 1
        assert graph.rosout.pid not in [p.pid for p in old_core]
    finally:
        graph.stop()
