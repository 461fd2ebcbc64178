"""FCLIB files: read as impacts with e = 0, solved exactly by Moreau's law with Coulomb cones.

The reader is checked against files written here with h5py in FCLIB's own layout
(``fclib.h``/``fclib.c`` of the FCLIB library: ``/fclib_local/W`` as a sparse matrix with
``nzmax, m, n, nz, p, i, x``; ``/fclib_local/vectors/q`` and ``mu``; ``spacedim``), and
against global problems that Siconos and LMGC90 wrote (``tests/data/fclib``), so that it is not
only held to our own writer.
"""

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import lawbench
from lawbench.files.fclib import fclib_diagnostics, read_fclib, write_fclib

h5py = pytest.importorskip("h5py")


def fclib_local(path, W, q, mu, layout):
    """Write a local FCLIB problem with W in the given sparse layout (triplet, csc, csr)."""
    with h5py.File(path, "w") as handle:
        root = handle.create_group("fclib_local")
        root.create_dataset("spacedim", data=np.array([3], dtype=np.int32))
        group = root.create_group("W")
        m, n = W.shape
        rows, cols = np.nonzero(W)
        if layout == "triplet":
            p, i, x, nz = (
                cols,
                rows,
                W[rows, cols],
                len(rows),
            )  # CSparse's triplets: i rows, p columns
        else:
            import scipy.sparse

            sparse = (scipy.sparse.csc_matrix if layout == "csc" else scipy.sparse.csr_matrix)(W)
            p, i, x, nz = sparse.indptr, sparse.indices, sparse.data, -1 if layout == "csc" else -2
        for key, value in (("nzmax", len(x)), ("m", m), ("n", n), ("nz", nz)):
            group.create_dataset(key, data=np.array([value], dtype=np.int32))
        group.create_dataset("p", data=np.asarray(p, dtype=np.int32))
        group.create_dataset("i", data=np.asarray(i, dtype=np.int32))
        group.create_dataset("x", data=np.asarray(x, dtype=float))
        vectors = root.create_group("vectors")
        vectors.create_dataset("q", data=q)
        vectors.create_dataset("mu", data=mu)


def random_local(rng, contacts):
    A = rng.normal(size=(3 * contacts, 3 * contacts))
    W = A @ A.T + 0.1 * np.eye(3 * contacts)
    q = rng.normal(size=3 * contacts)
    q[0::3] = -np.abs(q[0::3]) - 0.5  # every contact approaches
    return W, q, rng.uniform(0.1, 1.0, contacts)


def local_velocity_and_impulse(problem, outcome):
    """u = W.T v+ and r = (Pn, Pt) in FCLIB's per-contact order (n, t1, t2)."""
    m = problem.m
    u_n, u_t = problem.Wn.T @ outcome.v_plus, problem.Wt.T @ outcome.v_plus
    u = np.column_stack([u_n, u_t.reshape(m, 2)]).ravel()
    r = np.column_stack([outcome.Pn, outcome.Pt.reshape(m, 2)]).ravel()
    return u, r


@pytest.mark.parametrize("layout", ["triplet", "csc", "csr"])
@pytest.mark.parametrize("contacts", [1, 3])
def test_moreau_solves_the_fclib_local_problem(tmp_path, layout, contacts):
    """u = W r + q, r in the cones, De Saxce's complementarity (Acary et al., FCLIB, 2014)."""
    W, q, mu = random_local(np.random.default_rng(contacts), contacts)
    path = tmp_path / "local.hdf5"
    fclib_local(path, W, q, mu, layout)
    problem = read_fclib(path)
    assert [c.e for c in problem.contacts] == [0.0] * contacts
    outcome = lawbench.solve("moreau", problem)
    u, r = local_velocity_and_impulse(problem, outcome)
    scale = np.abs(q).max()
    assert np.abs(u - (W @ r + q)).max() <= 1e-9 * scale
    for j in range(contacts):
        un, ut, rn, rt = u[3 * j], u[3 * j + 1 : 3 * j + 3], r[3 * j], r[3 * j + 1 : 3 * j + 3]
        assert np.linalg.norm(rt) <= mu[j] * rn + 1e-9 * np.abs(r).max()
        modified = un + mu[j] * np.linalg.norm(ut)
        assert mu[j] * np.linalg.norm(ut) <= modified + 1e-8 * scale  # in the dual cone
        assert abs(modified * rn + ut @ rt) <= 1e-8 * scale * np.abs(r).max()


@pytest.mark.parametrize("case", ["rocking_block", "sphere_wall", "bouncing_ball"])
@pytest.mark.filterwarnings("ignore::lawbench.LossyExport")
def test_local_and_global_round_trips(tmp_path, case):
    problem = lawbench.CASES.get(case).build()
    local = read_fclib(write_fclib(problem, tmp_path / "local.h5", "local"))
    assert np.allclose(local.W.T @ local.v, problem.W.T @ problem.v, rtol=1e-12, atol=1e-14)
    assert np.allclose(local.contact_delassus, problem.contact_delassus, rtol=1e-10, atol=1e-12)
    global_ = read_fclib(write_fclib(problem, tmp_path / "global.h5", "global"))
    assert np.array_equal(global_.M, problem.M) and np.array_equal(global_.W, problem.W)
    assert np.allclose(global_.v, problem.v, rtol=1e-13, atol=1e-15)
    assert np.allclose(
        lawbench.solve("moreau", global_).v_plus,
        lawbench.solve(
            "moreau",
            problem.__class__.from_arrays(
                problem.M, problem.Wn, problem.v, problem.Wt, e=0.0, mu=problem.mu
            ),
        ).v_plus,
        atol=1e-10,
    )


def solved_from_the_command_line(folder, name):
    """The JSON record of ``lawbench solve moreau --problem NAME`` run in ``folder`` (exit 0)."""
    done = subprocess.run(
        [sys.executable, "-m", "lawbench", "solve", "moreau", "--problem", name, "--json"],
        capture_output=True,
        text=True,
        cwd=folder,
    )
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def test_solve_an_fclib_file_from_the_command_line(tmp_path):
    W, q, mu = random_local(np.random.default_rng(5), 2)
    fclib_local(tmp_path / "p.hdf5", W, q, mu, "csc")
    assert len(solved_from_the_command_line(tmp_path, "p.hdf5")["Pn"]) == 2


def test_a_file_that_is_not_an_impact_problem_is_refused_by_name(tmp_path):
    W, q, mu = random_local(np.random.default_rng(6), 1)
    path = tmp_path / "bad.hdf5"
    fclib_local(path, W, q, mu, "csc")
    with h5py.File(path, "a") as handle:
        del handle["fclib_local/vectors/q"]
    with pytest.raises(lawbench.InvalidProblem, match="vectors/q is missing"):
        read_fclib(path)


# Problems written by Siconos and LMGC90 (tests/data/fclib/README.md).
FIELD = sorted((Path(__file__).parent / "data" / "fclib").glob("*.hdf5"))


def coulomb_projection(x, mu):
    """Projection of (xn, xt1, xt2) onto the cone |xt| <= mu xn."""
    normal, tangent = x[0], x[1:]
    size = float(np.linalg.norm(tangent))
    if size <= mu * normal:
        return x
    if mu * size <= -normal:
        return np.zeros(3)
    a = (normal + mu * size) / (1 + mu * mu)
    return np.concatenate([[a], mu * a * tangent / size])


def triplets(group):
    """A sparse matrix of an FCLIB file in CSparse's triplets: row i[k], column p[k]."""
    import scipy.sparse

    nz = int(group["nz"][()].ravel()[0])
    shape = (int(group["m"][()].ravel()[0]), int(group["n"][()].ravel()[0]))
    rows, columns = group["i"][()][:nz], group["p"][()][:nz]
    return scipy.sparse.coo_matrix((group["x"][()][:nz], (rows, columns)), shape=shape).tocsr()


@pytest.mark.parametrize("path", FIELD, ids=[p.stem for p in FIELD])
def test_global_problems_from_siconos_and_lmgc90_are_solved_on_their_own_data(path):
    """Acary, Brémond and Huber's measure of a frictional contact solution, the natural map of
    De Saxce's complementarity, computed here from the file's own M, H, f, w and mu (read with
    h5py, not with the reader under test): v+ = M^-1 (H r + f), u = H.T v+ + w, and per contact
    r - P_K(r - (u + (mu |u_T|, 0, 0))) = 0. Moreau's law reaches it to 1e-8 relative."""
    with h5py.File(path, "r") as handle:
        root = handle["fclib_global"]
        M, H = triplets(root["M"]).toarray(), triplets(root["H"])
        vectors = {k: np.asarray(root["vectors"][k][()], dtype=float).ravel() for k in "fw"}
        mu = np.asarray(root["vectors"]["mu"][()], dtype=float).ravel()
    outcome = lawbench.LAWS["moreau"].resolve(read_fclib(path))
    assert outcome.Pn.size == mu.size == H.shape[1] // 3
    m = mu.size
    r = np.column_stack([outcome.Pn, outcome.Pt.reshape(m, 2)]).ravel()
    v = np.linalg.solve(M, H @ r + vectors["f"])
    np.testing.assert_allclose(v, outcome.v_plus, rtol=1e-9, atol=1e-9 * np.abs(v).max())
    u = H.T @ v + vectors["w"]
    residual = []
    for j in range(m):
        uj, rj = u[3 * j : 3 * j + 3], r[3 * j : 3 * j + 3]
        shifted = uj + np.array([mu[j] * np.linalg.norm(uj[1:]), 0.0, 0.0])
        residual.append(rj - coulomb_projection(rj - shifted, mu[j]))
    scale = max(np.abs(r).max(), np.abs(u).max())
    assert np.abs(residual).max() <= 1e-8 * scale
    assert fclib_diagnostics(path, outcome)["fc3d_error"] <= 1e-8


def test_the_fc3d_error_is_measured_on_the_files_own_asymmetric_w(tmp_path):
    """A local file whose W is not symmetric is solved on W's symmetric part; the diagnostics
    give the asymmetry and the FC3D error on the file's own W, which the symmetric answer
    misses by the asymmetry's order (Siconos' fc3d_compute_error: 2-norm of the natural map
    over max(|q|, |r|, |u|)). On the command line the JSON carries both."""
    W, q, mu = random_local(np.random.default_rng(11), 3)
    skew = np.triu(np.full_like(W, 1e-4), 1)
    fclib_local(tmp_path / "sym.hdf5", W, q, mu, "csc")
    fclib_local(tmp_path / "asym.hdf5", W + skew - skew.T, q, mu, "csc")
    symmetric = fclib_diagnostics(
        tmp_path / "sym.hdf5", lawbench.solve("moreau", read_fclib(tmp_path / "sym.hdf5"))
    )
    assert symmetric["W_asymmetry"] == 0.0 and symmetric["fc3d_error"] <= 1e-10
    outcome = lawbench.solve("moreau", read_fclib(tmp_path / "asym.hdf5"))
    found = fclib_diagnostics(tmp_path / "asym.hdf5", outcome)
    assert found["W_asymmetry"] == pytest.approx(2e-4 / np.abs(W + skew - skew.T).max())
    assert 1e-7 < found["fc3d_error"] < 1e-2
    record = solved_from_the_command_line(tmp_path, "asym.hdf5")
    assert record["diagnostics"]["fc3d_error"] == pytest.approx(found["fc3d_error"])


@pytest.mark.parametrize(
    ("layout", "key", "value", "message"),
    [
        ("triplet", "i", 99, r"/W/i \(rows\)\[\d+\] = 99 lies outside 0\.\.5"),
        ("triplet", "p", -1, r"/W/p \(columns\)\[\d+\] = -1 lies outside 0\.\.5"),
        ("csc", "i", 6, r"/W/i\[\d+\] = 6 lies outside 0\.\.5"),
        ("csc", "p", -3, r"/W/p must start at 0, never decrease"),
    ],
)
def test_an_index_outside_the_matrix_is_refused_by_name(tmp_path, layout, key, value, message):
    """A corrupt index array is refused before scipy sees it, naming the field and value."""
    W, q, mu = random_local(np.random.default_rng(3), 2)
    path = tmp_path / "bad.hdf5"
    fclib_local(path, W, q, mu, layout)
    with h5py.File(path, "r+") as handle:
        index = handle["fclib_local/W"][key]
        broken = index[()]
        broken[len(broken) // 2] = value
        index[...] = broken
    with pytest.raises(lawbench.InvalidProblem, match=message):
        read_fclib(path)


def test_the_rolling_friction_form_is_refused_by_name(tmp_path, capsys):
    """FCLIB's /fclib_global_rolling (fclib.h: rolling friction coefficients mu_r per contact)
    is recognised as FCLIB and refused as a problem no impact law here treats (exit 3)."""
    from lawbench.views import cli

    path = tmp_path / "rolling.hdf5"
    with h5py.File(path, "w") as handle:
        handle.create_group("fclib_global_rolling").create_dataset("spacedim", data=[5])
    with pytest.raises(lawbench.NotApplicable, match="rolling friction"):
        read_fclib(path)
    assert cli.main(["solve", "moreau", "--problem", str(path)]) == 3
    assert "fclib_global_rolling" in capsys.readouterr().err


def test_exporting_a_restitution_warns_that_fclib_holds_none(tmp_path, capsys):
    """FCLIB's problems are impacts with e = 0 (fclib.h stores W, q, mu and no restitution): a
    scene with a restitution coefficient is written as its plastic impact, and says so, in the
    API (a LossyExport warning) and on the command line (one line on stderr, exit 0)."""
    import warnings

    from lawbench.views import cli

    case = lawbench.CASES.get("sphere_wall")
    with pytest.warns(lawbench.LossyExport, match=r"plastic impact .* contacts \[0\] are left out"):
        write_fclib(case.build(e=1.0, e_t=0.0), tmp_path / "elastic.h5")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        write_fclib(case.build(e=0.0, e_t=0.0), tmp_path / "plastic.h5")
    with pytest.warns(lawbench.LossyExport, match="restitution"):
        write_fclib(case.build(e=0.0, e_t=0.5), tmp_path / "tangential.h5")
    out = tmp_path / "cli.h5"
    assert cli.main(["export", "sphere_wall", "--fclib", "local", "-o", str(out)]) == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("lawbench: warning: FCLIB holds no restitution")
    assert read_fclib(out).m == 1


@pytest.mark.parametrize(
    ("key", "value", "message"),
    [
        ("m", 10**8, "more than the 5e\\+07 entries"),
        ("m", 7, r"W is 7 x 6 .* need 6 x 6"),
        ("x", np.array([b"a"] * 6), "not numbers"),
    ],
)
def test_a_matrix_too_large_to_hold_or_not_numeric_is_refused(tmp_path, key, value, message):
    """A declared shape is bounded before anything is allocated, W is square with one row per
    contact coordinate, and its entries are numbers."""
    W, q, mu = random_local(np.random.default_rng(2), 2)
    path = tmp_path / "p.hdf5"
    fclib_local(path, W, q, mu, "csc")
    with h5py.File(path, "a") as handle:
        group = handle["fclib_local/W"]
        del group[key]
        group.create_dataset(key, data=np.atleast_1d(value))
    with pytest.raises(lawbench.InvalidProblem, match=message):
        read_fclib(path)


@pytest.mark.parametrize("case", ["billiard", "sphere_wall"])
def test_siconos_reads_and_solves_what_lawbench_writes(tmp_path, case):
    """Siconos' own FCLIB readers take lawbench's local and global files.

    Its NSGS (fc3d_nsgs) then finds the impulses Moreau's law gives on the same problem: at one
    frictional contact or two, where the Coulomb problem has one solution, they agree to 1e-8.
    Siconos' global reader copies ``nz`` indices whatever the storage, so lawbench writes
    triplets; the test runs wherever the ``siconos`` package is importable.
    """
    sn = pytest.importorskip("siconos.numerics", reason="Siconos' Python package is not installed")
    problem = lawbench.CASES[case].build(e=0.0)
    local, global_ = tmp_path / "local.hdf5", tmp_path / "global.hdf5"
    write_fclib(problem, local, "local")
    write_fclib(problem, global_, "global")
    read = sn.globalFrictionContact_fclib_read(str(global_))
    assert read.numberOfContacts == problem.m
    siconos_problem = sn.frictionContact_fclib_read(str(local))
    r, u = np.zeros(3 * problem.m), np.zeros(3 * problem.m)
    options = sn.SolverOptions(sn.SICONOS_FRICTION_3D_NSGS)
    options.iparam[0], options.dparam[0] = 10_000, 1e-12
    assert sn.fc3d_nsgs(siconos_problem, r, u, options) == 0
    outcome = lawbench.solve("moreau", read_fclib(local))
    ours = np.column_stack([outcome.Pn, outcome.Pt.reshape(problem.m, 2)]).ravel()
    np.testing.assert_allclose(r, ours, atol=1e-8)
