"""How long a heavy request holds up another client: one client calls get_world_properties back to
back (a persistent connection) while the main client makes each heavy request in turn; for each,
the worst get_world_properties round trip that overlapped it, against the worst of a quiet window
before any (the floor of the machine). The aim: no request blocks another client for more than
100 ms. Wall-clock figures, so a benchmark and never a test: run it on a quiet machine.

    python -m onedof_sim.benchmark.blocking_requests [--physics ode] [--quiet-s 3]
"""
import argparse
import multiprocessing
import time

from onedof_harness.private_ros import PrivateRos
from onedof_sim.engines import default_engine, engine_names, node_command

AIM_MS = 100
LINKS = 1000        # the most links a model may have
MOVING_JOINTS = 50  # the most the exact solver (the node's default) takes; the rest are fixed
REFUSED_LINKS = 3000


def box_inertial(urdf):
    """A 1 kg, 0.1 m solid box's inertial, as URDF or SDF."""
    if urdf:
        return ('<inertial><mass value="1"/><inertia ixx="0.00167" ixy="0" ixz="0" iyy="0.00167" '
                'iyz="0" izz="0.00167"/></inertial><collision><geometry><box size="0.1 0.1 0.1"/>'
                '</geometry></collision>')
    return ('<inertial><mass>1</mass><inertia><ixx>0.00167</ixx><iyy>0.00167</iyy>'
            '<izz>0.00167</izz><ixy>0</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>'
            '<collision name="c"><geometry><box><size>0.1 0.1 0.1</size></box></geometry>'
            '</collision>')


def chain_urdf(links):
    """A chain of boxes 0.12 m apart along x; its first MOVING_JOINTS joints revolute."""
    parts = ['<robot name="chain">']
    for i in range(links):
        parts.append('<link name="l%d">%s</link>' % (i, box_inertial(True)))
        if i:
            kind = 'revolute' if i <= MOVING_JOINTS else 'fixed'
            parts.append('<joint name="j%d" type="%s"><parent link="l%d"/><child link="l%d"/>'
                         '<origin xyz="0.12 0 0"/><axis xyz="0 1 0"/>'
                         '<limit lower="-1" upper="1" effort="10" velocity="1"/></joint>'
                         % (i, kind, i - 1, i))
    parts.append('</robot>')
    return ''.join(parts)


def chain_sdf(links):
    """The same chain as SDF (links placed in the model frame)."""
    parts = ['<?xml version="1.0"?><sdf version="1.6"><model name="chain">']
    for i in range(links):
        parts.append('<link name="l%d"><pose>%g 0 0 0 0 0</pose>%s</link>'
                     % (i, 0.12 * i, box_inertial(False)))
        if i:
            kind = 'revolute' if i <= MOVING_JOINTS else 'fixed'
            parts.append('<joint name="j%d" type="%s"><parent>l%d</parent><child>l%d</child>'
                         '<axis><xyz>0 1 0</xyz><limit><lower>-1</lower><upper>1</upper></limit>'
                         '</axis></joint>' % (i, kind, i - 1, i))
    parts.append('</model></sdf>')
    return ''.join(parts)


def prober(stop, results):
    """get_world_properties back to back until stop is set; sends [(start, end)] monotonic."""
    import rospy
    from gazebo_msgs.srv import GetWorldProperties
    proxy = rospy.ServiceProxy('/gazebo/get_world_properties', GetWorldProperties,
                               persistent=True)
    calls = []
    while not stop.is_set():
        started = time.monotonic()
        proxy()
        calls.append((started, time.monotonic()))
    results.send(calls)


def worst_overlapping(calls, start, end):
    """The longest call (s) that ran during [start, end], and how many did."""
    overlapping = [b - a for a, b in calls if b >= start and a <= end]
    return (max(overlapping) if overlapping else float('nan')), len(overlapping)


def heavy_requests():
    """(what, the call) in the order they run; each call returns the answer's text."""
    import rospy
    from gazebo_msgs.srv import DeleteModel, SpawnModel
    from geometry_msgs.msg import Pose
    from std_srvs.srv import Empty
    from onedof_sim.srv import StepSimulation

    def spawn(service, name, xml, z):
        pose = Pose()
        pose.position.z = z
        pose.orientation.w = 1.0
        answer = rospy.ServiceProxy('/gazebo/' + service, SpawnModel)(name, xml, '', pose, '')
        return '%s: %s' % (answer.success, answer.status_message[:100])

    def call(service, srv, *args):
        answer = rospy.ServiceProxy('/gazebo/' + service, srv)(*args)
        return '%s: %s' % (getattr(answer, 'success', ''), getattr(answer, 'status_message', '')[:100])

    return [
        ('spawn_urdf_model, %d links (%d revolute) accepted' % (LINKS, MOVING_JOINTS),
         lambda: spawn('spawn_urdf_model', 'big_urdf', chain_urdf(LINKS), 1)),
        ('spawn_sdf_model, %d links (%d revolute) accepted' % (LINKS, MOVING_JOINTS),
         lambda: spawn('spawn_sdf_model', 'big_sdf', chain_sdf(LINKS), 3)),
        ('spawn_sdf_model, %d links, refused' % REFUSED_LINKS,
         lambda: spawn('spawn_sdf_model', 'too_big', chain_sdf(REFUSED_LINKS), 5)),
        ('step_simulation, 100 steps with both in the air',
         lambda: call('step_simulation', StepSimulation, 100)),
        ('reset_simulation', lambda: call('reset_simulation', Empty)),
        ('delete_model, the URDF one', lambda: call('delete_model', DeleteModel, 'big_urdf')),
        ('delete_model, the SDF one', lambda: call('delete_model', DeleteModel, 'big_sdf')),
    ]


def run(physics, quiet_s):
    with PrivateRos() as ros:
        ros.adopt_environment()
        sim = ros.start(node_command(physics) + ['_paused:=true', '_enable_step_simulation:=true'],
                        name='sim')
        ros.wait_for_service('/gazebo/step_simulation', 60)
        stop = multiprocessing.Event()
        receive, send = multiprocessing.Pipe(duplex=False)
        probe = multiprocessing.Process(target=prober, args=(stop, send))
        probe.start()
        time.sleep(1)  # the prober connected and calling before the quiet window starts
        spans = [('(quiet: no other request)', time.monotonic(), None, '')]
        time.sleep(quiet_s)
        spans[0] = spans[0][:2] + (time.monotonic(), '')
        for what, request in heavy_requests():
            print('  ... ' + what, flush=True)
            started = time.monotonic()
            answer = request()
            spans.append((what, started, time.monotonic(), answer))
        stop.set()
        calls = receive.recv()
        probe.join(timeout=30)
        assert sim.poll() is None, 'the simulator exited: ' + ros.log_text(sim)[-2000:]
    print('get_world_properties while another client makes each request (%s, %d calls; aim: '
          'under %d ms):' % (physics, len(calls), AIM_MS))
    print('  %-50s %9s %12s %6s  %s' % ('request', 'took', 'worst call', 'calls', 'answer'))
    figures = []
    for what, start, end, answer in spans:
        worst, count = worst_overlapping(calls, start, end)
        figures.append((what, end - start, worst))
        print('  %-50s %7.0f ms %9.1f ms %6d  %s' % (what, 1000 * (end - start), 1000 * worst,
                                                   count, answer))
    return figures


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--physics', default=default_engine(), choices=engine_names())
    parser.add_argument('--quiet-s', type=float, default=3.0)
    args = parser.parse_args()
    run(args.physics, args.quiet_s)


if __name__ == '__main__':
    main()
