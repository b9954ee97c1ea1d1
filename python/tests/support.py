"""What the Python tests share: the source tree, the isoflex executable, a short model."""
import os
import subprocess
import tempfile

SOURCE_DIR = os.environ.get("ISOFLEX_SOURCE_DIR",
                            os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..")))
BINARY = os.environ.get("ISOFLEX_BINARY", os.path.join(SOURCE_DIR, "build", "isoflex"))


def example(*parts):
    return os.path.join(SOURCE_DIR, "examples", *parts)


def run_cli(*args):
    """Runs the isoflex tool; its exit code, stdout and stderr."""
    p = subprocess.run([BINARY, *args], capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def cli_history(model_file, *sets):
    """history.csv of `isoflex run MODEL --set ...` as a dict of columns (floats, exactly as
    written with 17 digits)."""
    with tempfile.TemporaryDirectory() as out:
        args = ["run", model_file, "-o", out, "--set", "output.vtk_every=0"]
        for s in sets:
            args += ["--set", s]
        code, _, err = run_cli(*args)
        if code != 0:
            raise RuntimeError(f"isoflex run failed ({code}): {err}")
        with open(os.path.join(out, "history.csv")) as f:
            header = f.readline().strip().split(",")
            rows = [[float(x) for x in line.split(",")] for line in f if line.strip()]
    return {name: [r[k] for r in rows] for k, name in enumerate(header)}
