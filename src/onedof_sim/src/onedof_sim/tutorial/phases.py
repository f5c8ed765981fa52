"""What the tutorial plays: its phases (the commands a student gives, the cafe table spawned
before the last) and the controller they command (its node, its joint, its period). Plain data:
the recorders, the runs, the predictions, the summary and the outputs share it."""
import collections

# table: the (x, y, z) where the cafe table is put before the phase's command (z = 0: on the
# ground), or None.
Phase = collections.namedtuple('Phase', 'name command table')

TABLE_X = 0.85


def spawn_table(x=TABLE_X, y=0.0, z=0.0):
    """The student's command that puts the cafe table at (x, y, z)."""
    return (['rosrun', 'gazebo_ros', 'spawn_model', '-database', 'cafe_table', '-sdf',
             '-model', 'cafe_table', '-x', repr(x)] + (['-y', repr(y)] if y else []) +
            (['-z', repr(z)] if z else []))


def with_table_at(phases, x, y=0.0, z=0.0):
    """phases with the cafe table put at (x, y, z) instead."""
    return tuple(phase._replace(table=(x, y, z)) if phase.table else phase for phase in phases)


PHASES = (
    Phase('command_1.0', 1.0, None),
    Phase('command_2.0', 2.0, None),
    Phase('upright_0.0', 0.0, None),
    Phase('table_2.5', 2.5, (TABLE_X, 0.0, 0.0)),
)
CONTROL_PERIOD = 0.01  # minimal_joint_controller's default 100 Hz
CONTROLLER_NODE = '/minimal_joint_controller'
JOINT = 'joint1'
