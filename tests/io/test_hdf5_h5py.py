#!/usr/bin/python3
"""results.h5 (output.hdf5) as h5py reads it: the layout of io/hdf5_results.hpp, the same numbers
as history.csv, probes.csv and resultants.csv (17 significant digits read back are the doubles),
the states at every k-th step and the last, and a file that is HDF5 but not isoflex's refused by
--restart. Run by ctest as io.hdf5_h5py with ISOFLEX_BINARY and ISOFLEX_SOURCE_DIR set."""
import csv
import json
import os
import shutil
import subprocess
import tempfile
import unittest

import h5py
import numpy as np

SOURCE_DIR = os.environ.get("ISOFLEX_SOURCE_DIR",
                            os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..")))
BINARY = os.environ.get("ISOFLEX_BINARY", os.path.join(SOURCE_DIR, "build", "isoflex"))
SLIDER_CRANK = os.path.join(SOURCE_DIR, "examples", "slider_crank_flexible", "model.yaml")

STATE_VECTORS = ["q", "v", "last_unknowns", "a", "aux", "lambda", "q_prev", "v_prev"]
STATE_SCALARS = ["step", "t", "grid_start", "grid_dt", "grid_steps", "last_dt", "last_start",
                 "dissipated", "external_work", "driver_work", "newton_iterations", "residual",
                 "path"]


def run(*args):
    p = subprocess.run([BINARY, *args], capture_output=True, text=True)
    return p.returncode, p.stdout + p.stderr


def read_csv(path):
    with open(path) as f:
        rows = list(csv.reader(f))
    return rows[0], rows[1:]


class ResultsFile(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.dir = tempfile.mkdtemp(prefix="isoflex_h5py_")
        cls.out = os.path.join(cls.dir, "out")
        code, text = run("run", SLIDER_CRANK, "-o", cls.out, "--set", "solver.t_end=0.3",
                         "--set", "output.vtk_every=0", "--set", "output.hdf5=true",
                         "--set", "output.hdf5_state_every=4")
        if code != 0:
            raise RuntimeError(f"isoflex run failed ({code}): {text}")
        cls.file = h5py.File(os.path.join(cls.out, "results.h5"), "r")

    @classmethod
    def tearDownClass(cls):
        cls.file.close()
        shutil.rmtree(cls.dir)

    def test_root_attributes(self):
        a = self.file.attrs
        self.assertEqual(a["isoflex_results"], 1)
        self.assertEqual(a["analysis"], "dynamic")
        self.assertEqual(a["formulation"], "reparametrized")
        self.assertEqual(a["model_file"], SLIDER_CRANK)
        self.assertEqual(a["model_name"], "slider_crank_flexible")
        self.assertEqual(a["dt"], 0.01)
        self.assertEqual(a["t_end"], 0.3)
        self.assertEqual(a["n"], 468)
        self.assertEqual(a["state_every"], 4)
        self.assertTrue(a["isoflex_version"].startswith("0."))
        with open(os.path.join(self.out, "summary.json")) as f:
            summary = json.load(f)
        self.assertEqual(a["energy_initial"], summary["energy_initial"])
        self.assertEqual(a["n"], summary["n_coordinates"])

    def test_history_equals_history_csv(self):
        header, rows = read_csv(os.path.join(self.out, "history.csv"))
        self.assertEqual(sorted(self.file["history"]), sorted(header))
        for k, name in enumerate(header):
            column = self.file["history"][name]
            self.assertEqual(column.dtype, np.float64)
            self.assertTrue(np.array_equal(column[:], [float(r[k]) for r in rows]), name)

    def test_probes_equal_probes_csv(self):
        _, rows = read_csv(os.path.join(self.out, "probes.csv"))
        self.assertEqual(sorted(self.file["probes"]), ["connection", "slider_end"])
        for name in self.file["probes"]:
            mine = [r for r in rows if r[1] == name]
            g = self.file["probes"][name]
            for key, first in (("position", 2), ("displacement", 5), ("velocity", 8)):
                expected = np.array([[float(x) for x in r[first:first + 3]] for r in mine])
                self.assertEqual(g[key].shape, (31, 3))
                self.assertTrue(np.array_equal(g[key][:], expected), f"{name}/{key}")

    def test_resultants_equal_resultants_csv(self):
        _, rows = read_csv(os.path.join(self.out, "resultants.csv"))
        for beam, elements in (("crank", 20), ("slider", 15)):
            mine = [r for r in rows if r[1] == beam]
            n = np.array([[float(x) for x in r[3:6]] for r in mine]).reshape(31, elements, 3)
            m = np.array([[float(x) for x in r[6:9]] for r in mine]).reshape(31, elements, 3)
            self.assertTrue(np.array_equal(self.file["resultants"][beam]["n"][:], n), beam)
            self.assertTrue(np.array_equal(self.file["resultants"][beam]["m"][:], m), beam)

    def test_states_of_every_kth_step_and_the_last(self):
        steps = sorted(self.file["steps"])
        self.assertEqual(steps, [f"{k:09d}" for k in list(range(0, 29, 4)) + [30]])
        t = self.file["history"]["t"][:]
        for name in steps:
            g = self.file["steps"][name]
            self.assertEqual(sorted(g), sorted(STATE_VECTORS))
            self.assertEqual(sorted(g.attrs), sorted(STATE_SCALARS))
            for v in STATE_VECTORS:
                self.assertEqual(g[v].dtype, np.float64)
                self.assertEqual(g[v].ndim, 1)
            self.assertEqual(g["q"].shape, (468,))
            self.assertEqual(g.attrs["step"], int(name))
            self.assertEqual(g.attrs["t"], t[int(name)])
        # The energy–momentum scheme keeps no q̈ (DAE only): empty datasets, not missing ones.
        self.assertEqual(self.file["steps"]["000000030"]["a"].shape, (0,))
        self.assertEqual(self.file["steps"]["000000000"]["last_unknowns"].shape, (0,))
        self.assertEqual(self.file["steps"]["000000030"]["last_unknowns"].shape, (214,))

    def test_a_restarted_file_says_where_it_started(self):
        out = os.path.join(self.dir, "restarted")
        code, text = run("run", SLIDER_CRANK, "-o", out, "--set", "solver.t_end=0.3",
                         "--set", "output.vtk_every=0", "--set", "output.hdf5=true",
                         "--restart", os.path.join(self.out, "results.h5"), "--from-step", "12")
        self.assertEqual(code, 0, text)
        with h5py.File(os.path.join(out, "results.h5"), "r") as f:
            self.assertEqual(f.attrs["restart_file"], os.path.join(self.out, "results.h5"))
            self.assertEqual(f.attrs["restart_from_step"], 12)
            self.assertEqual(f.attrs["energy_initial"], self.file.attrs["energy_initial"])
            self.assertTrue(np.array_equal(f["history"]["t"][:], self.file["history"]["t"][12:]))
            self.assertEqual(sorted(f["steps"])[0], "000000012")
            for v in STATE_VECTORS:
                self.assertTrue(np.array_equal(f["steps"]["000000030"][v][:],
                                               self.file["steps"]["000000030"][v][:]), v)


class NotAResultsFile(unittest.TestCase):
    def test_restart_refuses_another_hdf5_file(self):
        with tempfile.TemporaryDirectory() as d:
            other = os.path.join(d, "other.h5")
            with h5py.File(other, "w") as f:
                f.create_dataset("steps/000000000/q", data=np.zeros(468))
            code, text = run("run", SLIDER_CRANK, "-o", os.path.join(d, "out"), "--restart", other,
                             "--from-step", "0")
            self.assertEqual(code, 2, text)
            self.assertIn(f"error: --restart: {other}: not an isoflex results file", text)
            self.assertFalse(os.path.exists(os.path.join(d, "out")))


if __name__ == "__main__":
    unittest.main()
