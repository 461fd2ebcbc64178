"""Files: problems on disk, in lawbench's versioned format (JSON, NPZ, HDF5) and in FCLIB's.

Owns reading and writing problem files and the optional h5py dependency. May import
`lawbench.core` only.
"""
