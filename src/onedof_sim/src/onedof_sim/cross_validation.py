"""Cross-validation of the two physics engines, against the closed form and against each other.

Both engines run the same experiments in-process, step by step, with no ROS in between, so what
differs between them is physics and not message timing: the ODE core through the tool
`tutorial_scenario` (bench/tutorial_scenario.cpp), the pybullet core (BulletWorld) here. Each
experiment is defined once, below, and its figures are computed by the same code for both.

- release: the robot at rest at an angle with a constant effort on joint1; every step recorded.
  It gives the small-swing period, the energy over 10 s undamped and the static holding effort.
- the tutorial scenario: the tutorial controller's law every 10 ms of sim time (as
  minimal_joint_controller applies it: read q, qdot; an effort job for 10 ms from now), the
  tutorial player's phases and table. It gives the settled angles, the table-contact angle, and
  q(t) to compare between the engines.

    python -m onedof_sim.cross_validation [--markdown docs/cross_validation.md]
(under the workspace venv's python, where pybullet lives, with the devel space sourced).
"""
import argparse
import collections
import datetime
import math
import os
import subprocess
import sys

import rospkg

from minimal_joint_controller.control_law import pd_torque
from onedof_sim import tutorial_physics as physics
from onedof_sim.bullet_world import BulletWorld, ModelFormat, PhysicsParams, Pose, Vec3
from onedof_sim.tutorial_player import PHASES, TABLE_X

CONTROL_PERIOD_NS = 10000000  # the controller's 100 Hz
PHASE_SECONDS = 5.0
# The robot raised so that link2 hanging straight down clears the ground (its tip would touch it).
RELEASE_HEIGHT = 0.5
SWING_AMPLITUDE = 0.01   # rad from hanging straight down: T grows by amplitude^2 / 16, 6e-6 here
SWING_SECONDS = 10.0
ENERGY_START = 1.0       # rad
ENERGY_SECONDS = 10.0
HOLDING_ANGLES = (1.0, 2.0)
TABLE_PHASE = next(index for index, phase in enumerate(PHASES) if phase.before is not None)
# The last part of a phase over which its settled angle is averaged.
SETTLED_WINDOW = 0.5
# The aims (issue 5) for the RMS difference of the engines' q(t), per part of the scenario.
RMS_AIMS = collections.OrderedDict((('before the table', 0.01), ('with the table', 0.02)))

Run = collections.namedtuple('Run', 't q qdot torque')
# measured and closed_form are in unit.
Figure = collections.namedtuple('Figure', 'engine quantity unit measured closed_form')


def robot_urdf_path():
    return os.path.join(rospkg.RosPack().get_path('minimal_robot_description'),
                        'minimal_robot_description.urdf')


def table_sdf_path():
    return os.path.join(rospkg.RosPack().get_path('onedof_sim'), 'models', 'cafe_table',
                        'model.sdf')


def read_text(path):
    with open(path) as text:
        return text.read()


# --- the engines --------------------------------------------------------------------------------

def parse_csv(text):
    """A Run from the CSV the tool prints (t,q,qdot[,torque] with a header line)."""
    lines = text.strip().splitlines()
    header = lines[0].split(',')
    columns = {name: [] for name in header}
    for line in lines[1:]:
        for name, value in zip(header, line.split(',')):
            columns[name].append(float(value))
    return Run(columns['t'], columns['q'], columns['qdot'], columns.get('torque'))


class OdeEngine:
    """The ODE core, through `rosrun onedof_sim tutorial_scenario`."""
    name = 'ODE'

    def __init__(self, command=('rosrun', 'onedof_sim', 'tutorial_scenario')):
        self.command = list(command)

    def _run(self, args):
        done = subprocess.run(self.command + args, capture_output=True, text=True, timeout=600)
        if done.returncode != 0:
            raise RuntimeError('tutorial_scenario %s failed: %s' % (args[0], done.stderr.strip()))
        return parse_csv(done.stdout)

    def scenario(self, phase_seconds=PHASE_SECONDS):
        return self._run([
            'scenario', '--urdf', robot_urdf_path(), '--table', table_sdf_path(),
            '--table-x', repr(TABLE_X), '--table-phase', str(TABLE_PHASE),
            '--kp', repr(physics.KP), '--kv', repr(physics.KV),
            '--phase-seconds', repr(phase_seconds),
            '--commands', ','.join(repr(phase.command) for phase in PHASES)])

    def release(self, q, effort, seconds):
        return self._run(['release', '--urdf', robot_urdf_path(), '--z', repr(RELEASE_HEIGHT),
                          '--q', repr(q), '--effort', repr(effort), '--seconds', repr(seconds)])


def _checked(status):
    if not status.ok:
        raise RuntimeError(status.message)


class BulletEngine:
    """The pybullet core, in this process, with the default physics parameters or `params`."""
    name = 'bullet'

    def __init__(self, params=None):
        self.params = params

    def _world_with_robot(self, height):
        world = BulletWorld(self.params)
        _checked(world.spawn('one_DOF_robot', read_text(robot_urdf_path()), ModelFormat.URDF,
                             Pose(Vec3(0.0, 0.0, height))))
        return world

    @staticmethod
    def _joint1(world):
        status, info = world.joint_info('joint1')
        _checked(status)
        return info

    def scenario(self, phase_seconds=PHASE_SECONDS):
        world = self._world_with_robot(0.0)
        rows = []
        try:
            for phase in PHASES:
                if phase.before is not None:
                    _checked(world.spawn('cafe_table', read_text(table_sdf_path()),
                                         ModelFormat.SDF, Pose(Vec3(TABLE_X, 0.0, 0.0))))
                for _ in range(round(phase_seconds * 1e9 / CONTROL_PERIOD_NS)):
                    info = self._joint1(world)
                    torque = pd_torque(phase.command, info.position, info.rate, physics.KP,
                                       physics.KV)
                    _checked(world.apply_joint_effort('joint1', torque, world.time_ns(),
                                                      CONTROL_PERIOD_NS))
                    rows.append((round(world.time(), 3), info.position, info.rate, torque))
                    until = world.time_ns() + CONTROL_PERIOD_NS
                    while world.time_ns() < until:
                        world.step()
        finally:
            world.close()
        return Run(*(list(column) for column in zip(*rows)))

    def release(self, q, effort, seconds):
        world = self._world_with_robot(RELEASE_HEIGHT)
        rows = []
        try:
            _checked(world.set_model_configuration('one_DOF_robot', ['joint1'], [q]))
            if effort:
                _checked(world.apply_joint_effort('joint1', effort, 0, -1))
            until = round(seconds * 1e9)
            while True:
                info = self._joint1(world)
                rows.append((round(world.time(), 3), info.position, info.rate))
                if world.time_ns() >= until:
                    break
                world.step()
        finally:
            world.close()
        return Run(*(list(column) for column in zip(*rows)), None)


ENGINES = (OdeEngine, BulletEngine)


# --- figures ------------------------------------------------------------------------------------

def mean_period(times, positions, centre):
    """Mean period between the upward crossings of `centre`, each located by linear
    interpolation between the samples around it."""
    crossings = []
    for i in range(1, len(times)):
        before, after = positions[i - 1] - centre, positions[i] - centre
        if before < 0 <= after:
            crossings.append(times[i - 1] + (times[i] - times[i - 1]) * -before / (after - before))
    if len(crossings) < 2:
        raise ValueError('fewer than two upward crossings: the joint does not swing')
    return (crossings[-1] - crossings[0]) / (len(crossings) - 1)


def energy(q, qdot):
    """Kinetic plus potential energy of link2, the potential from its lowest centre of mass."""
    return (0.5 * physics.INERTIA_ABOUT_JOINT * qdot ** 2
            + physics.MASS * physics.GRAVITY * physics.COM_DISTANCE * (1 + math.cos(q)))


def holding_effort(engine, q):
    """The constant effort under which joint1, at rest at q, does not accelerate. From rest, the
    rate after one step is linear in the effort (no velocity terms yet), so two one-step releases,
    with no effort and with a probe effort, give it without assuming the link's inertia."""
    step = 0.001
    probe = 1.0
    free = engine.release(q, 0.0, step).qdot[-1]
    pushed = engine.release(q, probe, step).qdot[-1]
    return -probe * free / (pushed - free)


def phase_samples(run, index, phase_seconds=PHASE_SECONDS):
    """(times, positions) of the scenario's phase `index`."""
    start, end = index * phase_seconds, (index + 1) * phase_seconds
    pairs = [(t, q) for t, q in zip(run.t, run.q) if start <= t < end - 1e-9]
    return [t for t, _ in pairs], [q for _, q in pairs]


def settled(run, index, phase_seconds=PHASE_SECONDS):
    times, positions = phase_samples(run, index, phase_seconds)
    return physics.tail_mean(times, positions, SETTLED_WINDOW)


def closed_form_figures(engine, phase_seconds=PHASE_SECONDS, scenario=None):
    """The Figures of one engine against the closed form. `scenario`: its tutorial run if one is
    at hand (it is not run again)."""
    name = engine.name
    swing = engine.release(math.pi + SWING_AMPLITUDE, 0.0, SWING_SECONDS)
    figures = [Figure(name, 'small-swing period', 's', mean_period(swing.t, swing.q, math.pi),
                      physics.pendulum_period())]
    swinging = engine.release(ENERGY_START, 0.0, ENERGY_SECONDS)
    energies = [energy(q, qdot) for q, qdot in zip(swinging.q, swinging.qdot)]
    figures.append(Figure(name, 'energy after %g s undamped (from q = %g)'
                          % (ENERGY_SECONDS, ENERGY_START), 'J', energies[-1],
                          energy(ENERGY_START, 0.0)))
    figures.append(Figure(name, 'worst relative energy drift within %g s' % ENERGY_SECONDS, '',
                          max(abs(e / energies[0] - 1) for e in energies), 0.0))
    for q in HOLDING_ANGLES:
        figures.append(Figure(name, 'static holding effort at q = %g' % q, 'N m',
                              holding_effort(engine, q), -physics.gravity_torque(q)))
    scenario = scenario or engine.scenario(phase_seconds)
    for index, phase in enumerate(PHASES):
        if phase.before is None and phase.command:
            figures.append(Figure(name, 'settled angle, command %g' % phase.command, 'rad',
                                  settled(scenario, index, phase_seconds),
                                  physics.settled_angle(phase.command)))
    on_table = settled(scenario, TABLE_PHASE, phase_seconds)
    figures.append(Figure(name, 'table-contact angle, command %g, table at x = %g'
                          % (PHASES[TABLE_PHASE].command, TABLE_X), 'rad', on_table,
                          physics.table_contact_angle(TABLE_X)))
    figures.append(Figure(name, 'depth of the link\'s tip into the table top, at rest', 'mm',
                          tip_depth(on_table), 0.0))
    return figures


def tip_depth(q):
    """How far the leading rim of link2's tip is below the table top (m * 1000) at angle q."""
    return 1000 * (physics.TABLE_TOP_Z - physics.tip_rim(q)[1])


def rms(values):
    return math.sqrt(sum(v * v for v in values) / len(values))


def engine_differences(first, second, phase_seconds=PHASE_SECONDS):
    """{part of RMS_AIMS: (RMS, max |difference|) of q} between two runs of the scenario, sample
    by sample (the same control ticks)."""
    if first.t != second.t:
        raise ValueError('the two runs are not sampled at the same times')
    table_time = TABLE_PHASE * phase_seconds
    out = collections.OrderedDict()
    for part, with_table in zip(RMS_AIMS, (False, True)):
        differences = [a - b for t, a, b in zip(first.t, first.q, second.q)
                       if (t >= table_time - 1e-9) == with_table]
        out[part] = (rms(differences), max(abs(d) for d in differences))
    return out


def collect(phase_seconds=PHASE_SECONDS):
    """Everything the document shows: {'figures': the closed-form Figures of both engines,
    'differences': engine_differences of their scenario runs, 'without_slop': the same against
    bullet with contact_surface_layer 0 (where the difference on the table comes from)}."""
    runs, figures = {}, []
    for engine_class in ENGINES:
        engine = engine_class()
        runs[engine.name] = engine.scenario(phase_seconds)
        figures += closed_form_figures(engine, phase_seconds, runs[engine.name])
    without_slop = BulletEngine(PhysicsParams(contact_surface_layer=0.0)).scenario(phase_seconds)
    return {'figures': figures,
            'differences': engine_differences(runs['ODE'], runs['bullet'], phase_seconds),
            'without_slop': engine_differences(runs['ODE'], without_slop, phase_seconds)}


# --- the document -------------------------------------------------------------------------------

def _number(value):
    return '%.6g' % value


def _with_unit(text, unit):
    return text + ' ' + unit if unit else text


def _error(figure):
    error = figure.measured - figure.closed_form
    text = _with_unit('%+.3g' % error, figure.unit)
    if figure.closed_form:
        text += ' (%+.3g %%)' % (100 * error / abs(figure.closed_form))
    return text


def markdown(figures, differences, without_slop):
    lines = [
        '# Cross-validation of the physics engines',
        '',
        'Generated by `python -m onedof_sim.cross_validation --markdown docs/cross_validation.md`'
        ' (%s); the tests in `src/onedof_sim/test/test_cross_validation.py` assert these figures.'
        % datetime.date.today().isoformat(),
        '',
        'Both engines run the same experiments in-process, step by step at 1 ms, with no ROS in '
        'between: the ODE core through `tutorial_scenario`, the pybullet core through '
        '`BulletWorld`. The closed forms are those of `onedof_sim.tutorial_physics`.',
        '',
        '- Period: released %g rad from hanging straight down, %g s, mean period between upward '
        'crossings; closed form 2 pi sqrt(I / (m g d)).' % (SWING_AMPLITUDE, SWING_SECONDS),
        '- Energy: released at rest at q = %g, no damping, %g s; E = I qdot^2 / 2 + m g d '
        '(1 + cos q), which must stay E0.' % (ENERGY_START, ENERGY_SECONDS),
        '- Holding effort: the constant effort under which joint1 at rest does not accelerate '
        '(from two one-step releases); closed form -m g d sin q.',
        '- Settled and table-contact angles: the tutorial scenario (the controller\'s law every '
        '10 ms of sim time, Kp = %g, Kv = %g; commands %s, %g s each; the cafe table spawned at '
        'x = %g before command %g), mean q over the last %g s of the phase.'
        % (physics.KP, physics.KV, ', '.join('%g' % p.command for p in PHASES), PHASE_SECONDS,
           TABLE_X, PHASES[TABLE_PHASE].command, SETTLED_WINDOW),
        '',
        '| engine | quantity | measured | closed form | error |',
        '|---|---|---|---|---|',
    ]
    for figure in figures:
        lines.append('| %s | %s | %s | %s | %s |' % (
            figure.engine, figure.quantity, _with_unit(_number(figure.measured), figure.unit),
            _with_unit(_number(figure.closed_form), figure.unit), _error(figure)))
    lines += [
        '',
        '## ODE against bullet: q(t) over the tutorial scenario',
        '',
        'Sampled at the controller\'s ticks (every 10 ms of sim time).',
        '',
        '| part | RMS difference | max difference | aim | met |',
        '|---|---|---|---|---|',
    ]
    for part, (root_mean_square, worst) in differences.items():
        lines.append('| %s | %.3g rad | %.3g rad | < %g rad | %s |' % (
            part, root_mean_square, worst, RMS_AIMS[part],
            'yes' if root_mean_square < RMS_AIMS[part] else 'no'))
    lines += [
        '',
        'Before the table the engines differ only in how they write the joint down: ODE moves '
        'link2 as a free body held by a hinge constraint, bullet in joint coordinates '
        '(Featherstone). Both step semi-implicit Euler at 1 ms and q(t) agrees to the figures '
        'above. On the table the engines '
        'differ by how deep they let a contact sink (the depths in the first table): neither '
        'corrects an overlap smaller than `contact_surface_layer` (%g m by default; ODE\'s '
        'surface layer, bullet\'s contact slop). ODE keeps the link where the step that met the '
        'table left it; bullet pushes back only the overlap beyond its slop, so the link settles '
        'about that deep. With `contact_surface_layer` 0 in bullet, the RMS difference with the '
        'table becomes %.3g rad (max %.3g rad).'
        % ((PhysicsParams().contact_surface_layer,) + without_slop['with the table']),
    ]
    return '\n'.join(lines) + '\n'


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--markdown', metavar='PATH', help='write the tables to this file')
    args = parser.parse_args(argv)
    text = markdown(**collect())
    if args.markdown:
        with open(args.markdown, 'w') as out:
            out.write(text)
    sys.stdout.write(text)
    return 0


if __name__ == '__main__':
    sys.exit(main())
