"""`python -m xacro_ros1 FILE [name:=value ...]`: xacro's command line with ROS 1's substitution
args, within the limits of xacro_ros1.limits."""
import xacro

from xacro_ros1 import use_ros1_substitution_args
from xacro_ros1.limits import apply_limits

use_ros1_substitution_args()
apply_limits()
xacro.main()
