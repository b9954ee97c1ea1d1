"""The Python examples (examples/python): each runs, and its numbers are checked."""
import importlib.util
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

from support import SOURCE_DIR


def load(name):
    path = os.path.join(SOURCE_DIR, "examples", "python", f"{name}.py")
    spec = importlib.util.spec_from_file_location(name, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module, path


class ParameterSweep(unittest.TestCase):
    def test_orbits_grow_with_the_amplitude_and_energy_balances(self):
        sweep, _ = load("parameter_sweep")
        runs = sweep.sweep([0, 500, 1000], 0.5)
        self.assertEqual(runs[0]["orbit"].shape, (51, 3))
        # without the drive the system stays at rest
        self.assertEqual(np.abs(runs[0]["orbit"] - runs[0]["orbit"][0]).max(), 0.0)
        reach = [np.abs(runs[a]["orbit"] - runs[a]["orbit"][0]).max() for a in (500, 1000)]
        self.assertGreater(reach[0], 0.0)
        self.assertGreater(reach[1], reach[0])
        for a in (500, 1000):  # E − W = E₀: the conservation of DNSM-III with work of the load
            r = runs[a]
            balance = np.abs(r["energy"] - r["work"] - r["energy"][0]).max()
            self.assertLess(balance, 1e-9 * np.abs(r["work"]).max())

    def test_the_script_writes_its_figure(self):
        _, path = load("parameter_sweep")
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "sweep.png")
            p = subprocess.run([sys.executable, path, "--amplitudes", "500", "1000", "--t-end",
                                "0.3", "-o", out], capture_output=True, text=True)
            self.assertEqual(p.returncode, 0, p.stderr)
            self.assertTrue(os.path.getsize(out) > 0)
            self.assertIn("1000", p.stdout)


class Convergence(unittest.TestCase):
    def test_p_and_h_converge_to_the_kirchhoff_love_value(self):
        conv, _ = load("convergence")
        errors = [abs(conv.solve(2, n)[0] / conv.REFERENCE - 1) for n in (2, 4, 8)]
        self.assertTrue(errors[0] > errors[1] > errors[2], errors)
        u, unknowns = conv.solve(4, 8)
        self.assertAlmostEqual(u / conv.REFERENCE, 1.0, delta=1e-4)  # 0.3006 to 4 digits
        self.assertEqual(unknowns, 429)

    def test_the_script_writes_its_figure(self):
        _, path = load("convergence")
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "conv.png")
            p = subprocess.run([sys.executable, path, "--degrees", "3", "--elements", "2", "4",
                                "-o", out], capture_output=True, text=True)
            self.assertEqual(p.returncode, 0, p.stderr)
            self.assertTrue(os.path.getsize(out) > 0)
            self.assertEqual(len(os.listdir(d)), 1)  # the figure only: no result files


if __name__ == "__main__":
    unittest.main()
