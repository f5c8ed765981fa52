"""PyPI's xacro 2.x with ROS 1's substitution args: `$(find pkg)`, `$(arg)`, `$(env)`,
`$(optenv)`, `$(anon)`, `$(dirname)` and `$(eval)` are resolved by roslaunch's
substitution_args, as ROS 1's xacro resolves them (so $(find) is the package's folder on
ROS_PACKAGE_PATH, through rospkg, not ament's share folder). The command line, the macro
language and the error messages are PyPI's xacro unchanged."""
import functools

from roslaunch import substitution_args as roslaunch_args
from xacro import substitution_args as xacro_args


def use_ros1_substitution_args():
    """Points xacro's substitution args at roslaunch's, called as ROS 1's xacro calls them
    ($(anon) left as it is), with roslaunch's ArgException for xacro's "Undefined substitution
    argument" message."""
    xacro_args.resolve_args = functools.partial(roslaunch_args.resolve_args, resolve_anon=False)
    xacro_args.ArgException = roslaunch_args.ArgException
