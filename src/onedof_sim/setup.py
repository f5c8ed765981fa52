from setuptools import setup
from catkin_pkg.python_setup import generate_distutils_setup

setup(**generate_distutils_setup(packages=[
    'onedof_sim', 'onedof_sim.benchmark', 'onedof_sim.reference', 'onedof_sim.tools',
    'onedof_sim.tutorial'], package_dir={'': 'src'}))
