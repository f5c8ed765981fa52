"""Cross-validation of the physics engines, against the closed form and against an independent
reference.

Every engine runs the same experiments in-process, step by step, with no ROS in between, so what
differs between them is physics and not message timing: each of our engines (onedof_sim.engines)
through our model loader and the tool `tutorial_scenario --physics NAME`
(bench/tutorial_scenario.cpp), and pybullet through its own loaders
(onedof_sim.reference.pybullet_reference), the reference our engines are set against. Each
experiment is defined once, below, and its figures are computed by the same code for every engine.

- release: the robot at rest at an angle with a constant effort on joint1; every step recorded.
  It gives the small-swing period, the energy over 10 s undamped and the static holding effort.
- the tutorial scenario: the tutorial controller's law every 10 ms of sim time (as
  minimal_joint_controller applies it: read q, qdot; an effort job for 10 ms from now), the
  tutorial player's phases and table. It gives the settled angles, the table-contact angle, and
  q(t) to compare between the engines.
- beyond the tutorial's arm (onedof_sim.reference.engine_checks, our engines only): the book's
  diff-drive base, a force-torque joint and the base's lidar in a pen.

    python -m onedof_sim.reference.cross_validation [--markdown docs/cross_validation.md]
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

from onedof_sim.engines import engine_names
from onedof_sim.reference import engine_checks, pybullet_reference
from onedof_sim.tutorial import physics
from onedof_sim.tutorial.phases import PHASES, TABLE_X

PHASE_SECONDS = 5.0
# The robot raised so that link2 hanging straight down clears the ground (its tip would touch it).
RELEASE_HEIGHT = 0.5
SWING_AMPLITUDE = 0.01   # rad from hanging straight down: T grows by amplitude^2 / 16, 6e-6 here
SWING_SECONDS = 10.0
ENERGY_START = 1.0       # rad
ENERGY_SECONDS = 10.0
HOLDING_ANGLES = (1.0, 2.0)
TABLE_PHASE = next(index for index, phase in enumerate(PHASES) if phase.table is not None)
# The last part of a phase over which its settled angle is averaged.
SETTLED_WINDOW = 0.5
# The aims for the RMS difference of an engine's q(t) from the reference's, per part of
# the scenario.
RMS_AIMS = collections.OrderedDict((('before the table', 0.01), ('with the table', 0.02)))

TOOL = ('rosrun', 'onedof_sim', 'tutorial_scenario')

Run = collections.namedtuple('Run', 't q qdot torque')
# measured and closed_form are in unit.
Figure = collections.namedtuple('Figure', 'engine quantity unit measured closed_form')


def robot_urdf_path():
    return os.path.join(rospkg.RosPack().get_path('minimal_robot_description'),
                        'minimal_robot_description.urdf')


def table_sdf_path():
    return os.path.join(rospkg.RosPack().get_path('onedof_sim'), 'models', 'cafe_table',
                        'model.sdf')


def ground_sdf_path():
    return os.path.join(rospkg.RosPack().get_path('onedof_sim'), 'models', 'ground_plane',
                        'model.sdf')


# --- the engines --------------------------------------------------------------------------------

def parse_csv(text):
    """A Run from the CSV the tool prints (t,q,qdot[,torque] with a header line)."""
    columns = engine_checks.parse_columns(text)
    return Run(columns['t'], columns['q'], columns['qdot'], columns.get('torque'))


class ToolEngine:
    """One of our engines through our model loader: `rosrun onedof_sim tutorial_scenario MODE
    --physics NAME ...`."""

    def __init__(self, name):
        self.name = name

    def _run(self, mode, args):
        done = subprocess.run(list(TOOL) + [mode, '--physics', self.name,
                                            '--ground', ground_sdf_path()] + args,
                              capture_output=True, text=True, timeout=600)
        if done.returncode != 0:
            raise RuntimeError('tutorial_scenario %s --physics %s failed: %s'
                               % (mode, self.name, done.stderr.strip()))
        return parse_csv(done.stdout)

    def scenario(self, phase_seconds=PHASE_SECONDS):
        return self._run('scenario', [
            '--urdf', robot_urdf_path(), '--table', table_sdf_path(),
            '--table-x', repr(TABLE_X), '--table-phase', str(TABLE_PHASE),
            '--kp', repr(physics.KP), '--kv', repr(physics.KV),
            '--phase-seconds', repr(phase_seconds),
            '--commands', ','.join(repr(phase.command) for phase in PHASES)])

    def release(self, q, effort, seconds):
        return self._run('release', ['--urdf', robot_urdf_path(), '--z', repr(RELEASE_HEIGHT),
                                     '--q', repr(q), '--effort', repr(effort),
                                     '--seconds', repr(seconds)])


def transposed(rows):
    return [list(column) for column in zip(*rows)]


class PybulletReference:
    """pybullet through its own loaders, in this process; `contact_slop` in m."""
    name = 'pybullet'

    def __init__(self, contact_slop=pybullet_reference.CONTACT_SLOP):
        self.contact_slop = contact_slop

    def scenario(self, phase_seconds=PHASE_SECONDS):
        return Run(*transposed(pybullet_reference.scenario(
            robot_urdf_path(), table_sdf_path(), TABLE_X, TABLE_PHASE, physics.KP, physics.KV,
            phase_seconds, [phase.command for phase in PHASES], self.contact_slop)))

    def release(self, q, effort, seconds):
        return Run(*transposed(pybullet_reference.release(robot_urdf_path(), RELEASE_HEIGHT, q,
                                                        effort, seconds)), None)


def engines():
    """Our engines in registry order, then the reference."""
    return [ToolEngine(name) for name in engine_names()] + [PybulletReference()]


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
        if phase.table is None and phase.command:
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
    """Everything the document shows: {'figures': the closed-form Figures of every engine and of
    the reference, 'differences': {engine: engine_differences of its scenario run against the
    reference's}, 'without_slop': the same against the reference with contact slop 0 (where the
    difference on the table comes from)}."""
    reference = PybulletReference()
    reference_run = reference.scenario(phase_seconds)
    without_slop_run = PybulletReference(contact_slop=0.0).scenario(phase_seconds)
    figures = []
    differences, without_slop = collections.OrderedDict(), collections.OrderedDict()
    for name in engine_names():
        engine = ToolEngine(name)
        run = engine.scenario(phase_seconds)
        figures += closed_form_figures(engine, phase_seconds, run)
        differences[name] = engine_differences(run, reference_run, phase_seconds)
        without_slop[name] = engine_differences(run, without_slop_run, phase_seconds)
    figures += closed_form_figures(reference, phase_seconds, reference_run)
    checks = [check for name in engine_names()
              for check in engine_checks.checks(name, ground_sdf_path())]
    return {'figures': figures, 'differences': differences, 'without_slop': without_slop,
            'checks': checks}


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


def markdown(figures, differences, without_slop, checks=()):
    """The document: `figures` (Figures), `differences` and `without_slop` ({engine: {part of
    RMS_AIMS: (RMS, max)}}) and `checks` (engine_checks.Checks) as collect() returns them."""
    reference = PybulletReference.name
    lines = [
        '# Cross-validation of the physics engines',
        '',
        'Generated by `python -m onedof_sim.reference.cross_validation --markdown '
        'docs/cross_validation.md` (%s); the tests in '
        '`src/onedof_sim/test/test_cross_validation.py` assert these figures.'
        % datetime.date.today().isoformat(),
        '',
        'Every engine runs the same experiments in-process, step by step at 1 ms, with no ROS in '
        'between: our engines (%s) through our model loader and `tutorial_scenario --physics '
        'NAME`, and `%s`, the independent reference, through pybullet\'s own URDF and SDF '
        'loaders (`onedof_sim.reference.pybullet_reference`). The closed forms are those of '
        '`onedof_sim.tutorial.physics`.' % (', '.join(differences), reference),
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
        '## Each engine against %s: q(t) over the tutorial scenario' % reference,
        '',
        'Sampled at the controller\'s ticks (every 10 ms of sim time).',
        '',
        '| engine | part | RMS difference | max difference | aim | met |',
        '|---|---|---|---|---|---|',
    ]
    for engine, parts in differences.items():
        for part, (root_mean_square, worst) in parts.items():
            lines.append('| %s | %s | %.3g rad | %.3g rad | < %g rad | %s |' % (
                engine, part, root_mean_square, worst, RMS_AIMS[part],
                'yes' if root_mean_square < RMS_AIMS[part] else 'no'))
    lines += [
        '',
        'Before the table the engines differ in how they write the joint down: pybullet\'s loader '
        'builds a multibody in joint coordinates (Featherstone), our engines receive rigid bodies '
        'and the 1-DOF joints between them (src/core/engine.h); ode and bullet step those, dart '
        'and mujoco turn them back into joint coordinates (dart by Featherstone, as pybullet: '
        'the two agree to rounding). All step at 1 ms. On the table '
        'they differ by how deep they let a contact sink (the depths in the first table): '
        'pybullet leaves an overlap up to its contact slop (%g m, as ODE\'s contact surface '
        'layer) uncorrected, so the link settles about that deep. With the reference\'s contact '
        'slop 0, the RMS difference with the table becomes %s.'
        % (pybullet_reference.CONTACT_SLOP, ', '.join(
            '%.3g rad for %s (max %.3g rad)' % (parts['with the table'][0], engine,
                                                parts['with the table'][1])
            for engine, parts in without_slop.items())),
    ]
    if checks:
        lines += checks_section(checks)
    return '\n'.join(lines) + '\n'


def checks_section(checks):
    """The document's lines for engine_checks' Checks."""
    lines = [
        '',
        '## Each engine beyond the tutorial: a diff-drive base, a force-torque joint, a lidar, '
        'an arm',
        '',
        'Through `engine_checks --physics NAME` (`onedof_sim.reference.engine_checks`), the '
        'world calls each plugin makes, made directly:',
        '',
        '- The book\'s mobot (`bench/mobot_w_lidar.urdf`) on the ground, each wheel\'s velocity '
        'motor set every step as gazebo_ros_diff_drive sets it (rate (v -+ w s / 2) / r, at '
        'most %g N m); 1 s to reach the speed, then its mean speed along its heading and mean '
        'turn rate over %g s straight and %g s turning.'
        % (engine_checks.MOBOT['torque'], engine_checks.STRAIGHT[2], engine_checks.TURNING[2]),
        '- A %g kg block on a vertical slider whose stops hold it (the book\'s force-torque '
        'joint), under a base welded to the world: the constraint\'s force along z, mean of the '
        'last 0.1 s of 1 s; m g with g = %g.' % (engine_checks.HELD_MASS, physics.GRAVITY),
        '- The mobot at rest in a pen of four walls %g m from the origin: %d horizontal rays '
        'over its front half from the lidar\'s place (%g m ahead, %g m up), against the '
        'exact distance to the wall each meets.'
        % (engine_checks.PEN_HALF, engine_checks.LIDAR_SAMPLES, engine_checks.LIDAR_X,
           engine_checks.LIDAR_Z),
        '- An arm of the book\'s arm7dof\'s shape (`bench/arm7dof_shape.urdf`: its offsets, '
        'masses, damping) put at rest at the pose %s rad and held there by one '
        'effort_controllers/JointPositionController per joint, run every step as '
        'gazebo_ros_control runs them: its mean pose over the last 0.5 s against the droop, the '
        'pose where each joint\'s P term holds gravity\'s torque on the arm beyond it '
        '(computed from the arm\'s kinematics, each engine\'s own). With the P and D terms '
        'of the book\'s `arm7dof_pos_ctl.yaml` alone (p %s, d %s) for %g s the arm rests at '
        'the droop; with its I terms too (%s) for %g s it rests between its command and the '
        'droop, which the I terms take away over time.'
        % (_list(engine_checks.ARM_POSE), _list(engine_checks.ARM_GAINS['p']),
           _list(engine_checks.ARM_GAINS['d']), engine_checks.ARM_PD_SECONDS,
           _list(engine_checks.ARM_GAINS['i']), engine_checks.ARM_BOOK_SECONDS),
        '',
        '| engine | quantity | measured | expected | error | aim | met |',
        '|---|---|---|---|---|---|---|',
    ]
    for check in checks:
        figure = Figure(check.engine, check.quantity, check.unit, check.measured, check.expected)
        lines.append('| %s | %s | %s | %s | %s | within %s | %s |' % (
            check.engine, check.quantity, _with_unit(_number(check.measured), check.unit),
            _with_unit(_number(check.expected), check.unit), _error(figure),
            _with_unit('%.3g' % check.aim, check.unit), 'yes' if engine_checks.met(check) else
            'no'))
    missed = [check for check in checks if not engine_checks.met(check)]
    if missed:
        lines += ['', 'Not met: %s.' % ', '.join(
            '%s\'s %s (%s against %s)' % (check.engine, check.quantity,
                                           _with_unit(_number(check.measured), check.unit),
                                           _with_unit(_number(check.expected), check.unit))
            for check in missed)]
    return lines


def _list(values):
    return ', '.join('%g' % value for value in values)


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
