"""Item 8, stepping with in-simulator controllers: the tutorial robot with the book's
gazebo_ros_control tag and its two controllers (minimal_robot_in_sim_w_jnt_ctl.launch), stepped
through /gazebo/step_simulation, against the same node running free as fast as it can
(max_update_rate 0), in alternating windows of one run. Nothing outside the simulator takes part
in a period, so lock-step has nothing to wait for: stepping should run at the free loop's speed."""
import statistics
import time

from onedof_harness.private_ros import wait_until
from onedof_sim.benchmark.graph import STEP, NotMeasured
from onedof_sim.tutorial.runs import IN_SIM_CONTROLLERS, IN_SIM_NAMESPACE

AIM = 0.7  # of the free loop's steps per second
SETTLE_S = 0.25  # wall seconds after an unpause before a free window opens


def measure(bench, engine):
    what = ('steps/s of /gazebo/step_simulation with only in-simulator controllers (the book\'s '
            'gazebo_ros_control robot, joint_state_controller and joint1_position_controller; '
            'launch with physics:=%s)' % engine)
    try:
        stepped, free = windows(bench, engine)
    except (NotMeasured, TimeoutError) as error:
        bench.not_measured('8', what, str(error)[:300])
        return
    ratio = statistics.median(stepped) / statistics.median(free)
    bench.add('8', what, '%.0f' % statistics.median(stepped),
              'the same node running free (max_update_rate 0), in alternating windows',
              '%.0f' % statistics.median(free), ratio, aim='>= %g' % AIM, met=ratio >= AIM)
    bench.results['in_sim_stepping'] = dict(stepped=stepped, free=free, ratio=ratio)


def windows(bench, engine):
    """(steps/s stepped, steps/s free), one of each per window, alternating."""
    from controller_manager_msgs.srv import ListControllers
    from gazebo_msgs.srv import GetPhysicsProperties
    launch = bench.ros.start(['roslaunch', 'minimal_robot_description',
                              'minimal_robot_in_sim_w_jnt_ctl.launch', 'physics:=' + engine,
                              'paused:=true', 'max_update_rate:=0',
                              'enable_step_simulation:=true'], name='in_sim_' + engine)
    try:
        bench.wait_for_node(launch, '/gazebo')
        list_service = IN_SIM_NAMESPACE + '/controller_manager/list_controllers'
        bench.ros.wait_for_service(list_service, 60)
        list_controllers = bench.proxy(list_service, ListControllers)

        def running():
            states = {c.name: c.state for c in list_controllers().controller}
            return all(states.get(name) == 'running' for name in IN_SIM_CONTROLLERS)
        wait_until(running, 60, what='the spawner to start %s' % ', '.join(IN_SIM_CONTROLLERS))
        physics = bench.proxy('/gazebo/get_physics_properties', GetPhysicsProperties)()
        if abs(physics.max_update_rate) > 0 or abs(physics.time_step - STEP) > 1e-12:
            raise NotMeasured('the launch gave max_update_rate %g and time_step %g'
                              % (physics.max_update_rate, physics.time_step))
        step = bench.step_service(persistent=True)
        sim_time = bench.sim_clock()
        window_s = bench.sizes.throughput_window_s
        stepped, free = [], []
        for _ in range(bench.sizes.throughput_windows):
            steps_run, wall_s = bench.running_window(sim_time, SETTLE_S, window_s)
            free.append(steps_run / wall_s)
            steps = max(1, round(free[-1] * window_s))
            start = time.monotonic()
            reply = step(steps)
            wall = time.monotonic() - start
            if not reply.success:
                raise NotMeasured('step_simulation: ' + reply.status_message)
            stepped.append(steps / wall)
        return stepped, free
    finally:
        bench.stop(launch)
