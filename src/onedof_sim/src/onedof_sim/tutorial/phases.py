"""What the tutorial plays: its phases (the commands a student gives, the cafe table spawned
before the last) and the controller they command (its node, its joint, its period). Plain data:
the recorders, the runs, the predictions, the summary and the outputs share it."""
import collections

Phase = collections.namedtuple('Phase', 'name command before')

TABLE_X = 0.85
SPAWN_TABLE = ['rosrun', 'gazebo_ros', 'spawn_model', '-database', 'cafe_table', '-sdf',
               '-model', 'cafe_table', '-x', str(TABLE_X)]
PHASES = (
    Phase('command_1.0', 1.0, None),
    Phase('command_2.0', 2.0, None),
    Phase('upright_0.0', 0.0, None),
    Phase('table_2.5', 2.5, SPAWN_TABLE),
)
CONTROL_PERIOD = 0.01  # minimal_joint_controller's default 100 Hz
CONTROLLER_NODE = '/minimal_joint_controller'
JOINT = 'joint1'
