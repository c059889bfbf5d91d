# catkin_python_setup() reads this: the Python package nscd_sim lives in python/.
# Not for pip: the engine module is built by CMake (scripts/build.sh, docs/python.md).
from setuptools import setup
from catkin_pkg.python_setup import generate_distutils_setup

setup(**generate_distutils_setup(packages=['nscd_sim'], package_dir={'': 'python'}))
