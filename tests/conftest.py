import importlib.metadata
import importlib.util
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, settings

# Property tests run a fixed, derandomized example budget: the same examples on every run
# (a CI failure reproduces locally), and within the minute the fuzz tests may take in all.
settings.register_profile("dcfkit", max_examples=40, deadline=None, derandomize=True, database=None, print_blob=True,
                          suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture])
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "dcfkit"))

# the real development sequences: ../shared/data next to the checkout, or $DCFKIT_TEST_DATA
SHARED_DATA = Path(os.environ.get("DCFKIT_TEST_DATA") or Path(__file__).resolve().parents[2] / "shared" / "data")


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """The real benchmark sequences (skips when absent, as on a fresh machine)."""
    if not SHARED_DATA.is_dir():
        pytest.skip(f"real-data test: {SHARED_DATA} not found (present next to the project in CI; "
                    f"elsewhere set DCFKIT_TEST_DATA to the folder)")
    return SHARED_DATA


def pytest_addoption(parser, pluginmanager):
    """pyproject's ``addopts`` asks pytest-xdist (the test extras) for workers; without it
    (``pip install .`` alone, or ``-p no:xdist``) its options are accepted and the tests run in
    this one process, rather than pytest refusing them as unknown arguments (``addopts`` spells
    ``-n`` long: a short option only pytest itself may add)."""
    if not pluginmanager.hasplugin("xdist"):
        parser.addoption("--numprocesses", dest="numprocesses", help="(pytest-xdist is not installed)")
        parser.addoption("--maxprocesses", dest="maxprocesses", help="(pytest-xdist is not installed)")
        parser.addoption("--dist", dest="dist", help="(pytest-xdist is not installed)")


def pytest_collection_modifyitems(config, items):
    """Tiers: ``realdata`` (needs ../shared/data), ``install`` (pip-installs a copy), ``slow``
    (marked by hand: spawns worker processes or a cluster). The fast tier is
    ``python -m pytest -m "not realdata and not install and not slow"``.

    The files holding real-data tests run first: they take minutes each, and pytest-xdist hands
    out whole files in this order, so one of them collected last kept one worker busy alone."""
    for item in items:
        if "shared_data" in item.fixturenames:
            item.add_marker(pytest.mark.realdata)
        if "pip_install_copy" in item.fixturenames or item.path.name == "test_install.py":
            item.add_marker(pytest.mark.install)
    real = {item.path for item in items if item.get_closest_marker("realdata")}
    items.sort(key=lambda item: item.path not in real)  # stable: each file's order kept


@pytest.fixture(autouse=True)
def _single_threaded_openmp(monkeypatch):
    """OpenMP (numba, BLAS) in one thread unless the environment says otherwise: tests run
    side by side on two cores, and their subprocesses inherit it."""
    monkeypatch.setenv("OMP_NUM_THREADS", os.environ.get("OMP_NUM_THREADS", "1"))


# pip could not get setuptools/wheel for an isolated build: offline without a local index
OFFLINE = re.compile(r"No matching distribution|Could not find a version|NewConnectionError|"
                     r"Temporary failure in name resolution|Network is unreachable")


def local_build_backend() -> bool:
    """Can setuptools build a wheel here without downloading anything?"""
    try:
        version = importlib.metadata.version("setuptools")  # importing setuptools here would patch distutils
    except importlib.metadata.PackageNotFoundError:
        return False
    major, minor = (int(v) for v in re.findall(r"\d+", version)[:2])
    return (major, minor) >= (70, 1) or importlib.util.find_spec("wheel") is not None  # bdist_wheel


@pytest.fixture(scope="session")
def pip_install_copy(tmp_path_factory):
    """``install(source, git=False) -> site``: pip-install (no deps) a copy of a project folder
    into a fresh folder, as a user's ``pip install`` would, and return that folder (for
    PYTHONPATH). ``git``: the copy, ``site/../source``, is a git checkout of one commit, as a
    user's clone is."""

    def install(project: Path, git: bool = False) -> Path:
        if importlib.util.find_spec("pip") is None:
            pytest.skip("pip is not installed in this environment")
        tmp = tmp_path_factory.mktemp(project.name)
        source = tmp / "source"  # pip builds in the source tree: build a copy, leave the checkout clean
        shutil.copytree(project, source, ignore=shutil.ignore_patterns(
            "build", "*.egg-info", "__pycache__", ".git", ".ci-venv", "plugins", "tests", ".pytest_cache"))
        if git:
            _commit_all(source)
        target = tmp / "site"
        isolated = not local_build_backend()  # then pip fetches setuptools + wheel (a local index or PyPI)
        cmd = [sys.executable, "-m", "pip", "install", "--no-deps", "--no-input", "--disable-pip-version-check",
               "--target", str(target), str(source)] + ([] if isolated else ["--no-build-isolation"])
        try:
            done = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
        except subprocess.TimeoutExpired:
            if not isolated:
                raise
            pytest.skip("pip timed out fetching a build backend (setuptools + wheel)")
        if done.returncode != 0 and isolated and OFFLINE.search(done.stdout + done.stderr):
            pytest.skip("setuptools cannot build a wheel here (no 'wheel' package, setuptools < 70.1) and pip "
                        "could not download a build backend: " + (done.stderr.strip().splitlines() or ["?"])[-1])
        assert done.returncode == 0, f"{' '.join(cmd)} failed:\n{done.stdout}\n{done.stderr}"
        return target

    return install


def _commit_all(folder: Path) -> None:
    """Make ``folder`` a git checkout of one commit of all its files."""
    ident = ["-c", "user.name=dcfkit tests", "-c", "user.email=tests@dcfkit.invalid", "-c", "commit.gpgsign=false"]
    for args in (["init", "-q"], ["add", "-A"], ["commit", "-qm", "a user's clone"]):
        subprocess.run(["git", "-C", str(folder), *ident, *args], check=True, capture_output=True, timeout=60)


@pytest.fixture
def clobbered_opencv(tmp_path, monkeypatch):
    """cv2 as ``pip install opencv-python`` leaves it over dcfkit's contrib build (the two
    packages installed, as vot-toolkit's requirements make it): its own binary, with no Color
    Names table in it, and the contrib's ``cv2/legacy`` stub folder, importable and empty. A
    stand-in module, imported as cv2 by dcfkit too; no cached Color Names table."""
    import types  # deferred: only this fixture builds modules

    cv2 = types.ModuleType("cv2")
    cv2.__file__, cv2.__version__ = str(tmp_path / "__init__.py"), "5.0.0"
    cv2.legacy, cv2.TrackerMIL_create = types.ModuleType("cv2.legacy"), object
    (tmp_path / "cv2.abi3.so").write_bytes(b"\x7fELF not the contrib build")
    monkeypatch.setitem(sys.modules, "cv2", cv2)
    monkeypatch.setattr("dcfkit.integrations.opencv.cv2", cv2)
    monkeypatch.setattr("dcfkit.opencv_check.installed_opencv",
                        lambda: {"opencv-contrib-python-headless": "4.14.0.94", "opencv-python": "5.0.0.93"})
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    return cv2
