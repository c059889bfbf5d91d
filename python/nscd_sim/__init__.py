"""nscd_sim from Python: the engine (Simulator, State, SceneError, StateFileError,
SimulationError) and, in nscd_sim.study, a runner that maps cases over local cores or a
Dask cluster.

The engine is the compiled module nscd_sim._engine, built by scripts/build.sh into the
devel space, where this package also holds the ROS messages (nscd_sim.msg,
nscd_sim.srv); or, without ROS, by plain CMake into build/python (and installed into
PREFIX/lib/python3/dist-packages), without the messages. Reference: docs/python.md.
"""

# Imported straight from python/ (catkin's relay puts that folder on sys.path, and child
# processes inherit it), the package must still find the devel space's half: the
# engine module and the messages. extend_path adds every nscd_sim folder on sys.path.
from pkgutil import extend_path as _extend_path

__path__ = _extend_path(__path__, __name__)

try:
    from nscd_sim._engine import SceneError, SimulationError, Simulator, State, StateFileError  # noqa: F401
except ImportError as _engine_missing:  # the ROS message modules stay importable without it
    _ENGINE_IMPORT_ERROR = _engine_missing

    def __getattr__(name):
        if name in ('Simulator', 'State', 'SceneError', 'SimulationError', 'StateFileError'):
            raise ImportError('nscd_sim.%s: the engine module nscd_sim._engine is not built or not '
                              'found (%s); build with scripts/build.sh (needs pybind11-dev) and '
                              'source the devel space, or without ROS put build/python or '
                              'PREFIX/lib/python3/dist-packages on PYTHONPATH (docs/python.md)'
                              % (name, _ENGINE_IMPORT_ERROR))
        raise AttributeError('module nscd_sim has no attribute %r' % name)

__all__ = ['Simulator', 'State', 'SceneError', 'SimulationError', 'StateFileError']
