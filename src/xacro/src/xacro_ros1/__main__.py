"""`python -m xacro_ros1 FILE [name:=value ...]`: xacro's command line with ROS 1's substitution args."""
import xacro

from xacro_ros1 import use_ros1_substitution_args

use_ros1_substitution_args()
xacro.main()
