from setuptools import setup
from catkin_pkg.python_setup import generate_distutils_setup

# onedof_sim (src/) is the product; onedof_harness (harness/) is what the tests and the benchmark
# run around it. Each has a source root of its own: catkin's devel space puts a package's root on
# sys.path, and a root holding both would let the source onedof_sim shadow the devel one, which
# also carries the generated onedof_sim.srv.
setup(**generate_distutils_setup(packages=[
    'onedof_sim', 'onedof_sim.benchmark', 'onedof_sim.reference', 'onedof_sim.tools',
    'onedof_sim.tutorial', 'onedof_harness'],
    package_dir={'': 'src', 'onedof_harness': 'harness/onedof_harness'}))
