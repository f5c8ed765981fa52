"""Many clients at once: N clients, each spawning and deleting boxes back to back on fresh
connections (a service lookup at the roscore and a new TCP connection per call, as rosservice and
a non-persistent rospy ServiceProxy do), for a bounded time. Counts the calls, the failures by
service and reason, the models left behind, and the kernel's listen-queue overflows (its counters
of the network namespace this runs in: run it in a fresh one, `ip netns exec`, for clean figures).

    python -m onedof_sim.benchmark.concurrent_clients --clients 8 --seconds 60 [--physics ode]

--roscpp CALLS instead runs N roscpp clients (bench_service_client) making CALLS fresh-connection
get_joint_properties calls each on the tutorial robot, as fast as they can.
"""
import argparse
import collections
import multiprocessing
import os
import subprocess
import time

from onedof_harness.private_ros import PrivateRos, wait_until
from onedof_sim.engines import default_engine, engine_names, node_command

BOX_SDF = ('<?xml version="1.0"?><sdf version="1.6"><model name="box"><link name="body">'
           '<inertial><mass>1</mass><inertia><ixx>0.00667</ixx><iyy>0.00667</iyy>'
           '<izz>0.00667</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>'
           '<collision name="c"><geometry><box><size>0.2 0.2 0.2</size></box></geometry>'
           '</collision></link></model></sdf>')
KERNEL_COUNTERS = ('TcpExtListenOverflows', 'TcpExtListenDrops', 'TcpExtTCPReqQFullDrop',
                   'TcpExtTCPTimeWaitOverflow', 'TcpExtTCPAbortOnData')


def kernel_counters():
    """The listen-queue and abort counters of this network namespace (nstat, absolute)."""
    result = subprocess.run(['nstat', '-az'] + list(KERNEL_COUNTERS), capture_output=True,
                            text=True)
    counters = {}
    for line in result.stdout.splitlines():
        fields = line.split()
        if len(fields) >= 2 and fields[0] in KERNEL_COUNTERS:
            counters[fields[0]] = int(fields[1])
    return counters


def reason(error):
    """A failure's kind: the exception type and its message without the parts that vary."""
    text = str(error).split('\n')[0]
    for separator in (' [', ': [Errno', ' (http'):
        text = text.split(separator)[0]
    return '%s: %s' % (type(error).__name__, text[:120])


def client(index, seconds, results):
    import rospy
    from gazebo_msgs.srv import DeleteModel, GetWorldProperties, SpawnModel
    from geometry_msgs.msg import Pose
    pose = Pose()
    pose.position.z = 0.1 + index
    pose.orientation.w = 1.0
    calls = 0
    failures = collections.Counter()
    spent = collections.Counter()  # s in answered calls, by service
    answered = collections.Counter()
    deadline = time.monotonic() + seconds
    count = 0
    while time.monotonic() < deadline:
        name = 'box_%d_%d' % (index, count)
        count += 1
        for service, srv, args in (('spawn_sdf_model', SpawnModel, (name, BOX_SDF, '', pose, '')),
                                   ('get_world_properties', GetWorldProperties, ()),
                                   ('delete_model', DeleteModel, (name,))):
            calls += 1
            started = time.monotonic()
            try:
                rospy.ServiceProxy('/gazebo/' + service, srv)(*args)
                spent[service] += time.monotonic() - started
                answered[service] += 1
            except Exception as error:  # every failure is counted by kind, none ends the run
                failures[(service, reason(error))] += 1
    results.put((calls, dict(failures), dict(spent), dict(answered)))


def roscpp_clients(ros, clients, calls):
    """N bench_service_client processes, fresh connections; returns (calls, failures)."""
    urdf = subprocess.run(['rospack', 'find', 'minimal_robot_description'], capture_output=True,
                          text=True, check=True).stdout.strip() + '/minimal_robot_description.urdf'
    ros.run(['rosrun', 'gazebo_ros', 'spawn_model', '-file', urdf, '-urdf', '-model',
             'one_DOF_robot'])
    procs = [subprocess.Popen(['rosrun', 'onedof_sim', 'bench_service_client',
                               '/gazebo/get_joint_properties', 'get', 'fresh', str(calls)],
                              env=ros.env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                              text=True) for _ in range(clients)]
    lines = [line for proc in procs for line in proc.communicate(timeout=3600)[0].split()]
    return len(lines), collections.Counter({('get_joint_properties', 'no answer'):
                                            lines.count('failed')})


def run(clients, seconds, physics, roscpp_calls=None):
    with PrivateRos() as ros:
        ros.adopt_environment()
        sim = ros.start(node_command(physics), name='sim')
        ros.wait_for_service('/gazebo/delete_model', 60)
        before = kernel_counters()
        started = time.monotonic()
        if roscpp_calls:
            outcomes = [roscpp_clients(ros, clients, roscpp_calls) + ({}, {})]
        else:
            results = multiprocessing.Queue()
            workers = [multiprocessing.Process(target=client, args=(i, seconds, results))
                       for i in range(clients)]
            for worker in workers:
                worker.start()
            outcomes = [results.get(timeout=seconds + 120) for _ in workers]
            for worker in workers:
                worker.join(timeout=30)
        seconds = time.monotonic() - started
        after = kernel_counters()
        assert sim.poll() is None, 'the simulator exited: ' + ros.log_text(sim)[-2000:]
        models = ros.run(['rosservice', 'call', '/gazebo/get_world_properties']).stdout
    calls = sum(outcome[0] for outcome in outcomes)
    failures, spent, answered = collections.Counter(), collections.Counter(), collections.Counter()
    for _, failed, seconds_in, answers in outcomes:
        failures.update(failed)
        spent.update(seconds_in)
        answered.update(answers)
    left = [line.strip(' -') for line in models.splitlines() if line.strip().startswith('- box_')]
    print('%d %s clients, %.0f s on %s: %d calls, %d failed (%.3f %%), %d models left behind'
          % (clients, 'roscpp' if roscpp_calls else 'rospy', seconds, physics, calls, sum(failures.values()),
             100.0 * sum(failures.values()) / max(calls, 1), len(left)))
    if answered:
        print('mean round trip, fresh connection: %s' % ', '.join(
            '%s %.0f ms' % (service, 1000 * spent[service] / answered[service])
            for service in answered))
    for (service, why), count in failures.most_common():
        print('  %5d  %s  %s' % (count, service, why))
    print('kernel counters (this network namespace), during the run: %s'
          % {k: after.get(k, 0) - before.get(k, 0) for k in KERNEL_COUNTERS})
    return calls, failures, left


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--clients', type=int, default=8)
    parser.add_argument('--seconds', type=float, default=60)
    parser.add_argument('--physics', default=default_engine(), choices=engine_names())
    parser.add_argument('--roscpp', type=int, metavar='CALLS')
    args = parser.parse_args()
    run(args.clients, args.seconds, args.physics, args.roscpp)


if __name__ == '__main__':
    main()
