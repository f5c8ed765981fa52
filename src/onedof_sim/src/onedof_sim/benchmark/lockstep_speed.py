"""Item 8, lock-step speed: the real-time factor of the lock-stepped tutorial run as fast as the
controller allows (_lockstep:=true, _max_update_rate:=0, stepped with /gazebo/step_simulation),
with the rospy controller and the book-shaped C++ client, each at 100 Hz and 1 kHz, and the
lock-step timeouts the simulator logged. Each is set against its floor, measured just before and
just after it in the same run: the same controller against bench_lockstep_floor, which answers its
two calls and publishes the next period's /clock once the controller rests, with no world (the
least a lock-step partner can do). Beside each, what a period costs each side: the CPU time and the times put on a
CPU (wake-ups) of the simulator's and the controller's threads per period (Linux's schedstat),
where the period's wall time goes."""
import os
import re
import subprocess
import time

from onedof_harness import book_client
from onedof_harness.private_ros import wait_until
from onedof_sim.benchmark.graph import STEP, NotMeasured, by_path, node_label
from onedof_sim.tutorial import phases

COMMAND = 1.0  # the tutorial's first command step, rad
TIMEOUT_TEXT = 'lock-step: the world waited'  # the simulator's line when it gives up
# The aims: the real-time factor of each controller at each rate, or this share of its floor.
AIMS = {('rospy', 100): 25.0, ('cpp', 100): 50.0, ('rospy', 1000): 5.0, ('cpp', 1000): 5.0}
FLOOR_SHARE = 0.7
# Beyond this ratio (the simulator faster than its floor, more than run-to-run noise) the partner
# is not a floor for that controller.
NOT_A_FLOOR = 1.25
FLOOR_WARM_UP = 20  # periods before the floor's counted window (connections, first clock)
FLOOR_MAX_PERIODS = 2000  # a floor's period costs the same throughout: more adds only time
FLOOR_LINE = re.compile(r'floor: (\d+) periods in ([0-9.]+) s of wall time, ([0-9.]+) s of sim '
                        r'time, (\d+) wake-ups')


def measure(bench, engine):
    """The lock-stepped tutorial as fast as each controller allows: the rospy controller and the
    book-shaped C++ client, each at 100 Hz and at 1 kHz."""
    from std_msgs.msg import Float64
    # One publisher for every run: a latched rospy publisher unregistered and made again on the
    # same topic delivers nothing to the next subscriber.
    pos_cmd = bench.rospy.Publisher('/pos_cmd', Float64, queue_size=1, latch=True)
    try:
        if bench.book_client_overlay:
            setup = book_client.shared_overlay(bench.book_client_overlay)
        else:
            setup = book_client.build_overlay(bench.work)
        build_error = None
    except (RuntimeError, subprocess.TimeoutExpired) as error:
        setup, build_error = None, str(error)
    for rate in (100, 1000):
        controllers = [('rospy minimal_joint_controller', phases.CONTROLLER_NODE,
                        ['rosrun', 'minimal_joint_controller', 'minimal_joint_controller',
                         '_rate:=%g' % rate]),
                       ('book-shaped C++ client (%s)' % book_client.EXECUTABLES[rate],
                        book_client.NODE, book_client.command(setup, rate) if setup else None)]
        for label, node, command in controllers:
            what = ('real-time factor of the lock-stepped tutorial (_lockstep:=true, '
                    '_max_update_rate:=0: as fast as the controller allows), command step '
                    '0 -> %g at the start, %g s of sim time through /gazebo/step_simulation; '
                    '%s at %d Hz (%s)' % (COMMAND, bench.sizes.lockstep_s, label, rate,
                                          node_label(engine)))
            if command is None:
                bench.not_measured('8', what, 'the overlay build failed: ' + build_error[-200:])
                continue
            kind = 'cpp' if node == book_client.NODE else 'rospy'
            periods = min(FLOOR_MAX_PERIODS, max(1, round(bench.sizes.lockstep_s * rate)))
            try:
                # The floor just before and just after the simulator's run: the faster of the
                # two, the least a period costs this controller.
                floors = [floor_run(bench, command, node, 'floor_%s_%d_before' % (kind, rate),
                                    periods)]
                run = lockstep_run(bench, engine, command, node, 'lockstep_%s_%d' % (kind, rate),
                                   pos_cmd, rate)
                floors.append(floor_run(bench, command, node, 'floor_%s_%d_after' % (kind, rate),
                                        periods))
            except (NotMeasured, TimeoutError) as error:
                bench.not_measured('8', what, str(error)[:300])
                continue
            floor = max(floors, key=lambda f: f['rtf'])
            run['floors'] = floors
            aim = AIMS[(kind, rate)]
            share = run['rtf'] / floor['rtf']
            # A partner slower than the simulator bounds nothing: no claim then.
            met = None if share > NOT_A_FLOOR else (run['rtf'] >= aim or share >= FLOOR_SHARE)
            bench.add('8', what, '%.2f (lock-step timeouts in the simulator\'s log: %d)'
                      % (run['rtf'], run['timeouts']),
                      'its floor: the same controller against bench_lockstep_floor (its two calls '
                      'answered, /clock published once it rests, no world), %d periods, the '
                      'faster of a run before and one after' % floor['periods'],
                      '%.2f%s' % (floor['rtf'], (
                          ' (%d wake-ups)' % floor['wake_ups']) if floor['wake_ups'] else ''),
                      share, aim=None if met is None else '>= %g, or >= %g of the floor' % (
                          aim, FLOOR_SHARE), met=met)
            if met is None:
                bench.notes.append('8: %s at %d Hz: the floor partner ran %.1fx slower than the '
                                   'simulator with this controller, so it is no floor for it and '
                                   'the row claims nothing' % (label, rate, share))
            bench.notes.append('8: %s at %d Hz: per period, %.0f us of wall time; on a CPU: the '
                               'simulator\'s threads %s, the controller\'s %s' % (
                                   label, rate, run['wall_s'] / run['periods'] * 1e6,
                                   cost_text(run['sim_cost']), cost_text(run['controller_cost'])))
            if run['timeouts']:
                bench.notes.append('8: %s at %d Hz: the simulator gave up waiting %d times; '
                                   'the first: %s' % (label, rate, run['timeouts'],
                                                      run['timeout_lines'][0]))
            bench.results.setdefault('lockstep_speed', {})['%s at %d Hz' % (label, rate)] = run


def floor_run(bench, controller_command, node, name, periods):
    """The controller against bench_lockstep_floor standing in for the simulator (as /gazebo):
    the real-time factor over `periods` periods after FLOOR_WARM_UP, and the wake-ups the floor
    had to give in them."""
    bench.ros.set_param('/use_sim_time', True)
    floor = controller = None
    try:
        floor = bench.ros.start(by_path([
            'rosrun', 'onedof_sim', 'bench_lockstep_floor', '__name:=gazebo',
            '_controller:=' + node,
            '_start:=%g' % phases.CONTROL_PERIOD, '_periods:=%d' % periods,
            '_warm_up:=%d' % FLOOR_WARM_UP]), name=name)
        wait_until(lambda: bench.node_pid('/gazebo'), 60, what='bench_lockstep_floor')
        controller = bench.ros.start(by_path(controller_command), name=name + '_controller')

        def counted():
            for proc in (floor, controller):
                if proc.poll() is not None:
                    raise NotMeasured('%s exited: %s' % (proc.log_name,
                                                         bench.ros.log_text(proc)[-300:]))
            return FLOOR_LINE.search(bench.ros.log_text(floor))
        found = wait_until(counted, 120 + periods * 0.05,
                           what='%d periods of %s against the floor' % (periods, name))
    finally:
        for proc in (controller, floor):
            if proc:
                bench.stop(proc)
    wall, sim = float(found.group(2)), float(found.group(3))
    return dict(rtf=sim / wall, periods=int(found.group(1)), wall_s=wall, sim_s=sim,
                wake_ups=int(found.group(4)))


def lockstep_run(bench, engine, controller_command, node, name, pos_cmd, rate):
    """Starts the lock-stepped simulator paused with the tutorial's robot, steps it through one
    period so that the controller starts on a valid ROS time, starts the controller with the
    command latched on /pos_cmd, waits for it to join the lock-step and to hear /clock, and times
    /gazebo/step_simulation through lockstep_s of sim time. Returns the real-time factor, the
    lock-step timeouts the simulator logged and, per period of the controller (`rate` Hz), what
    the simulator's and the controller's threads cost."""
    sim = controller = None
    # The simulators of one engine share a log: this one's lines are those after this offset.
    log_start = len(bench.ros.log_text('sim_' + engine))

    def sim_log():
        return bench.ros.log_text(sim)[log_start:]
    try:
        sim, _ = bench.start_sim(engine, max_update_rate=0, paused=True, lockstep=True)
        bench.spawn(bench.tutorial_models[:1])
        step = bench.step_service()
        period_steps = round(phases.CONTROL_PERIOD / STEP)
        stepped(step, period_steps)
        pos_cmd.publish(pos_cmd.data_class(COMMAND))
        controller = bench.ros.start(by_path(controller_command), name=name)

        def joined():
            if controller.poll() is not None:
                raise NotMeasured('%s exited: %s' % (name, bench.ros.log_text(controller)[-300:]))
            return ('lock-step: joint1 is commanded by ' + node in sim_log()
                    and bench.hears_clock(node))

        def took_command():
            """Whether the controller has the command; if not, one more period of the world (the
            C++ client reads its subscriptions between periods)."""
            if 'received value of pos_cmd is: %f' % COMMAND in bench.ros.log_text(controller):
                return True
            stepped(step, period_steps)
            return False
        # A roscpp client can command before it has heard any /clock (its time still 0); its
        # ros::Rate then sleeps a whole period from the first time it hears, and a world stepped
        # on before that would wait for a command that comes a period too late. Its /clock
        # connection up, the latched time it hears first is the one the world stands at.
        wait_until(joined, 60, what='%s to join the lock-step and hear /clock' % name)
        # The latched command comes on a connection of its own, which on a busy machine may come
        # up after a short run's last period: the run starts once the controller has it.
        wait_until(took_command, 60, what='%s to take the command %g' % (name, COMMAND))
        steps = round(bench.sizes.lockstep_s / STEP)
        sim_pid, controller_pid = bench.node_pid('/gazebo'), bench.node_pid(node)
        start = time.monotonic()
        sim_start = stepped(step, 0)  # where the controller stands
        sim_before, controller_before = thread_times(sim_pid), thread_times(controller_pid)
        sim_end = stepped(step, steps)
        sim_after, controller_after = thread_times(sim_pid), thread_times(controller_pid)
        wall = time.monotonic() - start
        if controller.poll() is not None:
            raise NotMeasured('%s exited: %s' % (name, bench.ros.log_text(controller)[-300:]))
    finally:
        for proc in (controller, sim):
            if proc:
                bench.stop(proc)
    timeouts = [line for line in sim_log().splitlines() if TIMEOUT_TEXT in line]
    periods = max(1, round((sim_end - sim_start) * rate))
    return dict(rtf=(sim_end - sim_start) / wall, sim_s=sim_end - sim_start, wall_s=wall,
                timeouts=len(timeouts), timeout_lines=timeouts, periods=periods,
                sim_cost=per_period(sim_before, sim_after, periods),
                controller_cost=per_period(controller_before, controller_after, periods))


def thread_times(pid):
    """Each thread of a process by id: (ns on a CPU, times put on a CPU), from
    /proc/PID/task/*/schedstat; empty when the process is unknown or gone."""
    times = {}
    if not pid:
        return times
    task = '/proc/%d/task' % pid
    try:
        tids = os.listdir(task)
    except OSError:
        return times
    for tid in tids:
        try:
            with open('%s/%s/schedstat' % (task, tid)) as f:
                on_cpu_ns, _, runs = (int(field) for field in f.read().split()[:3])
        except (OSError, ValueError):
            continue  # a thread gone meanwhile
        times[tid] = (on_cpu_ns, runs)
    return times


def per_period(before, after, periods):
    """The CPU time (us) and the times put on a CPU per period, of every thread and of the one
    that took most, between two thread_times() of a process (threads started meanwhile from 0)."""
    deltas = [(on_cpu - before.get(tid, (0, 0))[0], runs - before.get(tid, (0, 0))[1])
              for tid, (on_cpu, runs) in after.items()]
    if not deltas:
        return None
    busiest = max(deltas)
    return dict(cpu_us=sum(d[0] for d in deltas) / 1e3 / periods,
                runs=sum(d[1] for d in deltas) / periods,
                busiest_thread_cpu_us=busiest[0] / 1e3 / periods,
                busiest_thread_runs=busiest[1] / periods)


def cost_text(cost):
    if not cost:
        return 'not read'
    return ('%.0f us and %.1f wake-ups (its busiest thread %.0f us, %.1f)'
            % (cost['cpu_us'], cost['runs'], cost['busiest_thread_cpu_us'],
               cost['busiest_thread_runs']))


def stepped(step, steps):
    """Sim seconds after /gazebo/step_simulation of `steps` (0: once the controllers have acted
    at the current time)."""
    reply = step(steps)
    if not reply.success:
        raise NotMeasured('step_simulation: ' + reply.status_message)
    return reply.sim_time.to_sec()
