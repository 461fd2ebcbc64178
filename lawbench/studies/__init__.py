"""The study engine: builds and runs every declared study and grid, and keeps what it found.

Owns studies (`Study`, its cells `Job` and the executor's `Plan`), the registry `STUDIES` that
builds them from the data the scenes and laws declare and the shapes they declare them with
(`lawbench.studies.declared`), grids and run files, the executor (serial, processes, Dask) with
its per-job guard, the tidy table of a run and its on-disk store, the regression baselines, the
fit of a law's coefficients to measurements, the conformance check of any law (`check_law`) and
the benchmark. May import the core, numerics, files, checks, and the laws and cases (through
their registries); never a view.
"""
