"""h5py, the optional dependency of every HDF5 problem file (lawbench's own format and FCLIB)."""

from types import ModuleType

from lawbench.core.errors import InvalidProblem


def require_h5py() -> ModuleType:
    """The h5py module, or an `InvalidProblem` that says which extra installs it."""
    try:
        import h5py
    except ImportError:  # an optional dependency: say how to get it
        raise InvalidProblem("HDF5 files need h5py: pip install 'lawbench[hdf5]'") from None
    return h5py
