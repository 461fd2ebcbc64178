"""FCLIB files: the global form read as an impact with e = 0, the local form as the
contact-space problem it is, both solved exactly by Moreau's law with Coulomb cones.

The reader is checked against files written here with h5py in FCLIB's own layout
(``fclib.h``/``fclib.c`` of the FCLIB library: ``/fclib_local/W`` as a sparse matrix with
``nzmax, m, n, nz, p, i, x``; ``/fclib_local/vectors/q`` and ``mu``; ``spacedim``), and
against global problems that Siconos and LMGC90 wrote (``tests/data/fclib``), so that it is not
only held to our own writer.
"""

import dataclasses
import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import lawbench
from lawbench import Contact
from lawbench.files.fclib import read_fclib, write_fclib
from lawbench.files.problem_files import read_problem

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


def assert_de_saxce(W, q, mu, r, tol):
    """u = W r + q, r in the cones, u + (mu |u_T|, 0, 0) in the dual cones, complementarity."""
    u = W @ r + q
    scale = max(np.abs(q).max(), np.abs(r).max())
    for j in range(mu.size):
        un, ut, rn, rt = u[3 * j], u[3 * j + 1 : 3 * j + 3], r[3 * j], r[3 * j + 1 : 3 * j + 3]
        assert np.linalg.norm(rt) <= mu[j] * rn + tol * scale
        modified = un + mu[j] * np.linalg.norm(ut)
        assert mu[j] * np.linalg.norm(ut) <= modified + tol * scale  # in the dual cone
        assert abs(modified * rn + ut @ rt) <= tol * scale * scale


@pytest.mark.parametrize("method", ["fixed_point", "nsgs"])
@pytest.mark.parametrize("layout", ["triplet", "csc", "csr"])
@pytest.mark.parametrize("contacts", [1, 3])
def test_moreau_solves_the_fclib_local_problem(tmp_path, layout, contacts, method):
    """u = W r + q, r in the cones, De Saxce's complementarity (Acary et al., FCLIB, 2014),
    checked here on the W, q and mu written, not on what the reader returned."""
    W, q, mu = random_local(np.random.default_rng(contacts), contacts)
    path = tmp_path / "local.hdf5"
    fclib_local(path, W, q, mu, layout)
    problem = read_fclib(path)
    assert isinstance(problem, lawbench.ContactProblem)
    solution = lawbench.LAWS["moreau"].solve_contact(problem, method=method)
    assert_de_saxce(W, q, mu, solution.r, 1e-8)
    assert solution.fc3d_error <= 1e-10
    np.testing.assert_allclose(solution.u, W @ solution.r + q, rtol=0, atol=1e-12)


@pytest.mark.parametrize("case", ["rocking_block", "sphere_wall", "bouncing_ball"])
@pytest.mark.filterwarnings("ignore::lawbench.LossyExport")
def test_local_and_global_round_trips(tmp_path, case):
    problem = lawbench.CASES.get(case).build()
    local = read_fclib(write_fclib(problem, tmp_path / "local.h5", "local"))
    m, d = problem.m, problem.d
    order = np.column_stack([np.arange(m), m + np.arange(m)[:, None] * d + np.arange(d)]).ravel()
    np.testing.assert_allclose(local.q, (problem.W.T @ problem.v)[order], rtol=1e-12, atol=1e-14)
    G = problem.contact_delassus[np.ix_(order, order)]
    np.testing.assert_allclose(local.W.toarray(), G, rtol=1e-10, atol=1e-12)
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


def solved_from_the_command_line(folder, name, *more):
    """The JSON record of ``lawbench solve moreau --problem NAME`` run in ``folder`` (exit 0)."""
    done = subprocess.run(
        [sys.executable, "-m", "lawbench", "solve", "moreau", "--problem", name, "--json", *more],
        capture_output=True,
        text=True,
        cwd=folder,
    )
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout)


def test_solve_an_fclib_file_from_the_command_line(tmp_path):
    W, q, mu = random_local(np.random.default_rng(5), 2)
    fclib_local(tmp_path / "p.hdf5", W, q, mu, "csc")
    record = solved_from_the_command_line(tmp_path, "p.hdf5")
    assert record["contacts"] == 2 and len(record["r"]) == len(record["u"]) == 6
    assert_de_saxce(W, q, mu, np.array(record["r"]), 1e-8)


def test_a_file_that_is_not_an_impact_problem_is_refused_by_name(tmp_path):
    W, q, mu = random_local(np.random.default_rng(6), 1)
    path = tmp_path / "bad.hdf5"
    fclib_local(path, W, q, mu, "csc")
    with h5py.File(path, "a") as handle:
        del handle["fclib_local/vectors/q"]
    with pytest.raises(lawbench.InvalidProblem, match="vectors/q is missing"):
        read_fclib(path)


# Problems written by Siconos and LMGC90 (tests/data/fclib/README.md).
DATA = Path(__file__).parent / "data" / "fclib"
GLOBAL = sorted(path for path in DATA.glob("*.hdf5") if "fclib_global" in h5py.File(path, "r"))
LOCAL = sorted(path for path in DATA.glob("*.hdf5") if path not in GLOBAL)
# A global form whose M is not symmetric: no impact problem (tests/data/fclib/README.md).
NOT_AN_IMPACT = DATA / "LMGC_GlobalFrictionContactProblem00046.hdf5"
FIELD = [path for path in GLOBAL if path != NOT_AN_IMPACT]


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
    assert read_problem(path).facts.diagnostics(outcome)["fc3d_error"] <= 1e-8


# Granular problems take thousands of Gauss-Seidel sweeps, above Moreau's default bound.
GRANULAR_SWEEPS = 100_000
# What each committed local file holds that a factorization W = Wc.T Wc, q = Wc.T v cannot.
AS_GIVEN = {
    "LMGC_100_PR_PerioBox-i00361-60-03000": ("q outside the range of W", 0.2, 0.0),
    "Capsules-i125-1213": ("W asymmetric", 0.0, 1e-3),
}
SOLVED = [path for path in LOCAL if path.stem in AS_GIVEN]


@pytest.mark.parametrize("path", SOLVED, ids=[p.stem for p in SOLVED])
def test_local_problems_from_siconos_and_lmgc90_are_solved_as_given(path):
    """The local files Siconos and LMGC90 wrote are solved on their own W and q, read here with
    h5py in compressed rows (nz = -2), not with the reader under test: De Saxce's conditions
    hold, the FC3D error is at most 1e-8, and so is every approach (relative to |q|; impulses
    of 1e5 against a W of 1e-5 once let an answer leave a contact approaching at 4e-3 of |q|
    pass). The PerioBox file's q has a part outside the range
    of W (27 % of |q|: W has rank 72 of 180), which no factorization W = Wc.T Wc with
    q = Wc.T v can represent; the Capsules file's W is asymmetric by 1.3e-3, which the solve
    reports and keeps."""
    import scipy.sparse

    with h5py.File(path, "r") as handle:
        root = handle["fclib_local"]
        group = root["W"]
        shape = (int(group["m"][()].ravel()[0]), int(group["n"][()].ravel()[0]))
        assert int(group["nz"][()].ravel()[0]) == -2
        W = scipy.sparse.csr_matrix((group["x"][()], group["i"][()], group["p"][()]), shape=shape)
        q = np.asarray(root["vectors"]["q"][()], dtype=float).ravel()
        mu = np.asarray(root["vectors"]["mu"][()], dtype=float).ravel()
    values, vectors = np.linalg.eigh(((W + W.T) / 2).toarray())
    outside = q - vectors[:, values > 1e-12 * values.max()] @ (
        vectors[:, values > 1e-12 * values.max()].T @ q
    )
    solution = lawbench.LAWS["moreau"].solve_contact(
        read_fclib(path), method="nsgs", tol=1e-8, max_steps=GRANULAR_SWEEPS
    )
    assert solution.fc3d_error <= 1e-8
    assert solution.u[::3].min() >= -1e-8 * np.linalg.norm(q)
    assert_de_saxce(W, q, mu, solution.r, 1e-6)
    asymmetry = abs(W - W.T).max() / abs(W).max()
    assert solution.diagnostics["W_asymmetry"] == pytest.approx(asymmetry)
    _, least_outside, least_asymmetry = AS_GIVEN[path.stem]
    assert np.linalg.norm(outside) >= least_outside * np.linalg.norm(q)
    assert asymmetry >= least_asymmetry


@pytest.mark.parametrize("method", ["nsgs", "fixed_point"])
def test_a_global_form_that_is_no_impact_is_solved_in_contact_space(method):
    """LMGC90's global problem 00046 has an M that is not symmetric (largest |M - M.T| = 39.2),
    which no impact problem has: it is read as Siconos reformulates it, W = H.T M^-1 H and
    q = H.T M^-1 f + w, computed here with h5py and numpy from the file's own M, H, f and w,
    and solved to an FC3D error of 1e-10 on them."""
    with h5py.File(NOT_AN_IMPACT, "r") as handle:
        root = handle["fclib_global"]
        M, H = triplets(root["M"]).toarray(), triplets(root["H"]).toarray()
        f, w = (np.asarray(root["vectors"][k][()], dtype=float).ravel() for k in "fw")
        mu = np.asarray(root["vectors"]["mu"][()], dtype=float).ravel()
    assert np.abs(M - M.T).max() > 39
    W, q = H.T @ np.linalg.solve(M, H), H.T @ np.linalg.solve(M, f) + w
    problem = read_fclib(NOT_AN_IMPACT)
    assert isinstance(problem, lawbench.ContactProblem)
    assert "M is not symmetric" in problem.name
    np.testing.assert_allclose(problem.W.toarray(), W, rtol=0, atol=1e-12 * np.abs(W).max())
    np.testing.assert_allclose(problem.q, q, rtol=0, atol=1e-12 * np.abs(q).max())
    solution = lawbench.LAWS["moreau"].solve_contact(problem, method=method)
    assert solution.fc3d_error <= 1e-10
    assert_de_saxce(W, q, mu, solution.r, 1e-8)


def test_a_global_form_with_an_offset_is_read_in_contact_space(tmp_path):
    """An offset w (a constant local velocity) has no impact counterpart: the file is read as
    q = H.T M^-1 f + w, W = H.T M^-1 H, and the offset is named."""
    problem = lawbench.CASES["billiard"].build(e=0.0)
    path = write_fclib(problem, tmp_path / "offset.hdf5", "global")
    with h5py.File(path, "r+") as handle:
        w = handle["fclib_global/vectors/w"]
        w[...] = np.linspace(-0.1, 0.1, w.shape[0])
        offset = w[()]
    read = read_fclib(path)
    assert isinstance(read, lawbench.ContactProblem) and "w, a constant local velocity" in read.name
    m, d = problem.m, problem.d
    order = np.column_stack([np.arange(m), m + np.arange(m)[:, None] * d + np.arange(d)]).ravel()
    q = (problem.W.T @ problem.v)[order] + offset
    np.testing.assert_allclose(read.q, q, rtol=0, atol=1e-12 * np.abs(q).max())


def test_a_global_file_held_sparse_gives_the_dense_answer(monkeypatch):
    """Global files whose matrices are large are held sparse (Siconos' Spheres file has a
    12000 x 12000 M): read so, the Box_Stacks file gives the impulses of its dense reading to
    rounding, with NSGS on the sparse Delassus matrix."""
    from lawbench.files import fclib

    path = next(p for p in FIELD if p.stem.startswith("Box_Stacks"))
    dense = read_fclib(path)
    monkeypatch.setattr(fclib, "DENSE_ENTRIES", 100)
    sparse = read_fclib(path)
    assert sparse.sparse and not dense.sparse
    moreau = lawbench.LAWS["moreau"]
    held_sparse = moreau.resolve(sparse, method="nsgs", tol=1e-10)
    held_dense = moreau.resolve(dense, method="nsgs", tol=1e-10)
    scale = np.abs(held_dense.Pn).max()
    np.testing.assert_allclose(held_sparse.Pn, held_dense.Pn, rtol=0, atol=1e-8 * scale)
    assert read_problem(path).facts.diagnostics(held_sparse)["fc3d_error"] <= 1e-10


@pytest.mark.parametrize("method", ["nsgs", "fixed_point"])
def test_an_asymmetric_w_is_solved_as_given_and_its_asymmetry_reported(tmp_path, method):
    """A local file whose W is not symmetric is solved on the file's own W to an FC3D error of
    1e-10 (the natural map in units of velocity and the approaches, over max(|q|, |u|)):
    NSGS sweeps W as given, the fixed point's cone QPs take W's symmetric part and iterate the
    rest with the friction term. The diagnostics give the asymmetry; Anitescu's relaxation,
    one convex problem, refuses it by name. On the command line the JSON carries both."""
    W, q, mu = random_local(np.random.default_rng(11), 3)
    skew = np.triu(np.full_like(W, 1e-4), 1)
    fclib_local(tmp_path / "asym.hdf5", W + skew - skew.T, q, mu, "csc")
    problem = read_fclib(tmp_path / "asym.hdf5")
    moreau = lawbench.LAWS["moreau"]
    solution = moreau.solve_contact(problem, method=method)
    assert solution.diagnostics["W_asymmetry"] == pytest.approx(
        2e-4 / np.abs(W + skew - skew.T).max()
    )
    assert solution.fc3d_error <= 1e-10
    assert_de_saxce(W + skew - skew.T, q, mu, solution.r, 1e-8)
    with pytest.raises(lawbench.NotApplicable, match=r"asymmetry is 2\.\d+e-05"):
        moreau.solve_contact(problem, friction="relaxed")
    record = solved_from_the_command_line(tmp_path, "asym.hdf5", "--option", f"method={method}")
    assert record["fc3d_error"] == pytest.approx(solution.fc3d_error, abs=1e-13)
    assert record["diagnostics"]["W_asymmetry"] == solution.diagnostics["W_asymmetry"]


def test_a_law_without_a_contact_space_solver_refuses_a_local_problem(tmp_path, capsys):
    """Only a law that solves Coulomb's problem in contact space takes FCLIB's local form;
    the others say why (exit 3 on the command line)."""
    from lawbench.views import cli

    W, q, mu = random_local(np.random.default_rng(4), 2)
    fclib_local(tmp_path / "p.hdf5", W, q, mu, "csc")
    problem = read_fclib(tmp_path / "p.hdf5")
    with pytest.raises(lawbench.NotApplicable, match="generalized coordinates"):
        lawbench.LAWS["whittaker"].solve_contact(problem)
    assert cli.main(["solve", "newton", "--problem", str(tmp_path / "p.hdf5")]) == 3
    assert "contact-space problem" in capsys.readouterr().err


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
        ("m", 10**8, r"W is 100000000 x 6 .* need 6 x 6"),
        ("m", 7, r"W is 7 x 6 .* need 6 x 6"),
        ("x", np.array([b"a"] * 6), "not numbers"),
    ],
)
def test_a_matrix_too_large_to_hold_or_not_numeric_is_refused(tmp_path, key, value, message):
    """W is held sparse whatever its declared shape, is square with one row per contact
    coordinate, and its entries are numbers."""
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
    ours = lawbench.LAWS["moreau"].solve_contact(read_fclib(local)).r
    np.testing.assert_allclose(r, ours, atol=1e-8)


def with_friction(source, path, mu):
    """A global FCLIB file: ``source`` (a file, or a scene's problem written here) at ``mu``."""
    if isinstance(source, Path):
        shutil.copyfile(source, path)
    else:
        write_fclib(source, path, "global")
    with h5py.File(path, "r+") as handle:
        handle["fclib_global/vectors/mu"][...] = mu
    return read_problem(path)


@pytest.mark.parametrize("method", ["nsgs", "fixed_point"])
def test_a_global_form_at_mu_1e6_is_solved_to_tol_on_its_own_data(tmp_path, method):
    """LMGC90's four contacts at mu = 1e6, solved to tol = 1e-6: on the file's own M, H, f
    and w (read here with h5py), no contact approaches by more than tol of |q|, and the natural
    map with each impulse in velocities (``W_jj r_j``) is at most tol of the velocities. The
    sweeps stopped at a natural map relative to impulses of 1e4, which in velocities was
    2.2e-5 on the file's data, 22 times the tolerance."""
    path = next(p for p in FIELD if p.stem.startswith("LMGC_GFC3D-i00501"))
    read = with_friction(path, tmp_path / "stiff.hdf5", 1e6)
    outcome = lawbench.LAWS["moreau"].resolve(read.problem, method=method, tol=1e-6)
    with h5py.File(tmp_path / "stiff.hdf5", "r") as handle:
        root = handle["fclib_global"]
        M, H = triplets(root["M"]).toarray(), triplets(root["H"]).toarray()
        f, w = (np.asarray(root["vectors"][k][()], dtype=float).ravel() for k in "fw")
    r = np.column_stack([outcome.Pn, outcome.Pt.reshape(-1, 2)]).ravel()
    u = H.T @ np.linalg.solve(M, H @ r + f) + w
    W, q = H.T @ np.linalg.solve(M, H), H.T @ np.linalg.solve(M, f) + w
    scale = max(np.linalg.norm(q), np.linalg.norm(u))
    assert u[::3].min() >= -1e-6 * scale
    residual = []
    for j in range(4):
        uj, zj = u[3 * j : 3 * j + 3], W[3 * j, 3 * j] * r[3 * j : 3 * j + 3]
        shifted = uj + np.array([1e6 * np.linalg.norm(uj[1:]), 0.0, 0.0])
        residual.append(zj - coulomb_projection(zj - shifted, 1e6))
    assert np.linalg.norm(residual) <= 1e-6 * scale
    assert read.facts.diagnostics(outcome)["fc3d_error"] <= 1e-6


def test_a_sticking_contact_at_mu_1e6_is_measured_to_rounding(tmp_path):
    """A global form's W = H.T M^-1 H and the impact's Wc.T M^-1 Wc differ by rounding, which
    the modified velocity multiplies by mu at a sticking contact's u_T: the pencil's exact
    answer on its own W measured 1.05e-10 on the file's at mu = 1e6, above the default
    tol = 1e-10. Each velocity is now given its rounding."""
    pencil = lawbench.CASES["bouncing_pencil"].build(e=0.0)
    sticking = dataclasses.replace(pencil, contacts=[Contact(e=0.0, mu=1e6)])
    read = with_friction(sticking, tmp_path / "pencil.hdf5", 1e6)
    outcome = lawbench.LAWS["moreau"].resolve(read.problem)
    assert np.linalg.norm(outcome.Pt) > 0.1 * outcome.Pn[0]  # a tangential impulse: it sticks
    assert read.facts.diagnostics(outcome)["fc3d_error"] <= 1e-10
