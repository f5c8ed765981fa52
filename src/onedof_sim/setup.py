from setuptools import setup
from catkin_pkg.python_setup import generate_distutils_setup

# onedof_sim is the product; onedof_harness is what the tests and the benchmark run around it.
setup(**generate_distutils_setup(packages=[
    'onedof_sim', 'onedof_sim.benchmark', 'onedof_sim.reference', 'onedof_sim.tools',
    'onedof_sim.tutorial', 'onedof_harness'], package_dir={'': 'src'}))
