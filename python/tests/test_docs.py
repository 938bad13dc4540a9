"""Every ```python block of README.md and docs/*.md runs as written (docs/DESIGN.md, "Examples
that run"): each in a fresh interpreter, in a directory where the README's ```sh setup blocks
ran (the recordings the examples read) and testdata/ is linked, failing on an exception or a
ResourceWarning (a file left open). `/dev/ttyUSB0` and `/dev/ttyUSB1` are virtual ESCs on
pseudo-terminals (`hwfoc simulate --pty`); a block that receives MAVLink (`mavutil`) runs while
`hwfoc bridge --sim 4 --mavlink udp` sends to it."""

import os
import re
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import ROOT

DOCUMENTS = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def blocks(path: Path):
    """The fenced blocks of a document: (place, info string, text)."""
    found = []
    lines = path.read_text().splitlines()
    start = None
    for n, line in enumerate(lines):
        if start is None and line.startswith("```"):
            start, info, body = n, line[3:].strip(), []
        elif start is not None and line == "```":
            found.append((f"{path.relative_to(ROOT)}:{start + 1}", info, "\n".join(body) + "\n"))
            start = None
        elif start is not None:
            body.append(line)
    return found


PYTHON_BLOCKS = [b for doc in DOCUMENTS for b in blocks(doc) if b[1] == "python"]
SETUP = [b for b in blocks(ROOT / "README.md") if b[1] == "sh setup"]


def test_the_documents_have_python_examples():
    assert PYTHON_BLOCKS, "no ```python block in README.md or docs/"
    assert SETUP, "README.md: no ```sh setup block"


def _env(cli, home):
    # The interpreter's own directory first, as in an activated virtual environment (Spark's
    # workers start `python3` from PATH).
    path = os.pathsep.join([str(Path(cli).resolve().parent), str(Path(sys.executable).parent),
                            os.environ.get("PATH", "")])
    env = dict(os.environ, PATH=path, HOME=str(home))
    env.pop("HWFOC_CONFIG", None)
    env.pop("XDG_CONFIG_HOME", None)
    return env


@pytest.fixture(scope="module")
def workdir(tmp_path_factory, cli):
    """A directory where the README's setup blocks ran."""
    d = tmp_path_factory.mktemp("docs")
    (d / "testdata").symlink_to(ROOT / "testdata")
    for place, _, text in SETUP:
        p = subprocess.run(["bash", "-e", "-o", "pipefail", "-c", text], cwd=d, env=_env(cli, d),
                           capture_output=True, text=True, timeout=300)
        assert p.returncode == 0, f"{place}: {p.stderr}"
    return d


def _start(cli, *args):
    return subprocess.Popen([cli, *args], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)


def _stop(process):
    process.send_signal(signal.SIGTERM)
    try:
        process.wait(timeout=10)
    except subprocess.TimeoutExpired:
        process.kill()
        process.wait()


@pytest.mark.parametrize("place,code", [(b[0], b[2]) for b in PYTHON_BLOCKS], ids=[b[0] for b in PYTHON_BLOCKS])
def test_python_example_runs(place, code, workdir, cli):
    helpers = []
    try:
        if "/dev/ttyUSB" in code:
            ports = workdir / f"ports-{os.getpid()}-{time.monotonic_ns()}"
            helpers.append(_start(cli, "simulate", "--escs", "2", "--pty", "-q", "--duration", "300",
                                  "--link-dir", ports))
            deadline = time.monotonic() + 20
            while not all((ports / f"esc{i}").exists() for i in range(2)):
                assert time.monotonic() < deadline, "the virtual ESCs' links"
                time.sleep(0.05)
            for i in range(2):
                code = code.replace(f"/dev/ttyUSB{i}", str(ports / f"esc{i}"))
        if "mavutil" in code:
            helpers.append(_start(cli, "bridge", "--sim", "4", "--mavlink", "udp", "--duration", "120", "-q"))
        p = subprocess.run([sys.executable, "-W", "always::ResourceWarning", "-c", code], cwd=workdir,
                           env=_env(cli, workdir), capture_output=True, text=True, timeout=600)
    finally:
        for helper in helpers:
            _stop(helper)
    assert p.returncode == 0, f"{place}:\n{code}\nstandard error:\n{p.stderr}"
    assert "ResourceWarning" not in p.stderr, f"{place}: a resource left open:\n{p.stderr}"
