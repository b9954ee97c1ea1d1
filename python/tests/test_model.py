"""isoflex.Model, isoflex.check and isoflex.cad_info (docs/python.md)."""
import os
import re
import unittest

import yaml

import isoflex
from support import example, run_cli

SLIDER_CRANK = example("slider_crank_flexible", "model.yaml")


class ModelFromFile(unittest.TestCase):
    def test_reads_the_file(self):
        m = isoflex.Model(SLIDER_CRANK)
        self.assertEqual(m.data.dt, 0.01)
        self.assertEqual(m.data.t_end, 10)
        self.assertEqual(m.data.formulation, "reparametrized")
        self.assertEqual(m.data.bodies, ["pyramid_a", "pyramid_b"])
        self.assertEqual(m.data.probes, ["connection", "slider_end"])

    def test_set_overrides_a_value_and_a_bad_one_is_located(self):
        m = isoflex.Model(SLIDER_CRANK)
        m.set("solver.dt", 1e-3).set("bodies[pyramid_b].mass", 2)
        self.assertEqual(m.data.dt, 1e-3)
        with self.assertRaises(isoflex.ModelError) as c:
            m.set("solver.dt", -1)
        self.assertEqual(c.exception.key, "solver.dt")
        self.assertIn("--set solver.dt=-1", str(c.exception))
        self.assertEqual(m.data.dt, 1e-3)  # the bad value was not kept
        with self.assertRaises(isoflex.ModelError) as c:
            m.set("bodies[nobody].mass", 1)
        self.assertIn("nobody", str(c.exception))

    def test_a_missing_file_is_a_model_error(self):
        with self.assertRaises(isoflex.ModelError) as c:
            isoflex.Model("/nonexistent/model.yaml")
        self.assertEqual(c.exception.file, "/nonexistent/model.yaml")
        self.assertIsInstance(c.exception, ValueError)
        self.assertIsInstance(c.exception, isoflex.Error)

    def test_an_error_in_the_file_names_file_line_and_key(self):
        with open(SLIDER_CRANK) as f:
            text = f.read().replace("mass: 1.0", "mass: -1.0", 1)
        path = os.path.join(os.environ.get("TMPDIR", "/tmp"), f"isoflex_bad_{os.getpid()}.yaml")
        with open(path, "w") as f:
            f.write(text)
        try:
            with self.assertRaises(isoflex.ModelError) as c:
                isoflex.Model(path)
        finally:
            os.remove(path)
        line = next(k + 1 for k, s in enumerate(text.splitlines()) if "mass: -1.0" in s)
        self.assertEqual((c.exception.file, c.exception.line, c.exception.key),
                         (path, line, "bodies[0].mass"))


class ModelFromDict(unittest.TestCase):
    def setUp(self):
        with open(SLIDER_CRANK) as f:
            self.d = yaml.safe_load(f)

    def test_a_dict_runs_like_its_file(self):
        a = isoflex.Simulation(isoflex.Model(SLIDER_CRANK).set("solver.t_end", 0.05))
        b = isoflex.Simulation(isoflex.Model(self.d).set("solver.t_end", 0.05))
        ra, rb = a.run(), b.run()
        self.assertEqual(len(ra["t"]), 6)
        for column in ra:
            if column != "probes":
                self.assertEqual(list(ra[column]), list(rb[column]), column)
        self.assertEqual(list(a.state.q), list(b.state.q))

    def test_errors_name_the_key_path(self):
        self.d["bodies"][1]["mass"] = -2.0
        with self.assertRaises(isoflex.ModelError) as c:
            isoflex.Model(self.d)
        e = c.exception
        self.assertEqual((e.file, e.line, e.key), ("<dict>", 0, "bodies[1].mass"))
        self.assertTrue(str(e).startswith("<dict>: bodies[1].mass: "), str(e))

    def test_an_unknown_key_is_named(self):
        self.d["solver"]["dtt"] = 0.1
        with self.assertRaises(isoflex.ModelError) as c:
            isoflex.Model(self.d)
        self.assertIn("solver.dtt", str(c.exception))

    def test_values_that_are_no_model_values_are_refused(self):
        self.d["solver"]["dt"] = object()
        with self.assertRaises(TypeError) as c:
            isoflex.Model(self.d)
        self.assertIn("solver.dt", str(c.exception))

    def test_strings_with_yaml_syntax_stay_strings(self):
        self.d["loads"][0]["force"] = ["1000*sin(_pi*t)*(t<=2)", "0: #", "0"]
        with self.assertRaises(isoflex.ModelError) as c:
            isoflex.Model(self.d)
        self.assertEqual(c.exception.key, "loads[0].force[1]")


class Check(unittest.TestCase):
    def test_figures_are_those_of_the_check_command(self):
        figures = isoflex.check(SLIDER_CRANK)
        code, out, _ = run_cli("check", SLIDER_CRANK)
        self.assertEqual(code, 0)
        self.assertEqual(figures["report"], out)
        cli = {k: int(v) for k, v in re.findall(r"^(n|m|dof|tree coordinates) +(\d+)", out, re.M)}
        self.assertEqual(figures["n"], cli["n"])
        self.assertEqual(figures["m"], cli["m"])
        self.assertEqual(figures["dof"], cli["dof"])
        self.assertEqual(figures["tree_coordinates"], cli["tree coordinates"])
        u = re.search(r"unknowns +constrained (\d+), nullspace (\d+), reparametrized (\d+)", out)
        self.assertEqual(figures["unknowns"], {"constrained": int(u[1]), "nullspace": int(u[2]),
                                               "reparametrized": int(u[3])})

    def test_a_static_model(self):
        figures = isoflex.check(example("scordelis_lo", "kl_shell.yaml"))
        _, out, _ = run_cli("check", example("scordelis_lo", "kl_shell.yaml"))
        self.assertEqual(figures["analysis"], "static")
        self.assertEqual(figures["unknowns"], int(re.search(r"^unknowns +(\d+)", out, re.M)[1]))


class CadInfo(unittest.TestCase):
    def test_patches_of_a_step_file(self):
        info = isoflex.cad_info(example("kl_twist_beam", "twist_beam.stp"))
        self.assertEqual(info["format"], "STEP")
        self.assertGreaterEqual(len(info["patches"]), 1)
        code, out, _ = run_cli("cad-info", example("kl_twist_beam", "twist_beam.stp"))
        self.assertEqual(code, 0)
        p = info["patches"][0]
        self.assertIn(f"degrees         {p['degrees'][0]} x {p['degrees'][1]}", out)
        self.assertIn(f"control points  {p['control_points'][0]} x {p['control_points'][1]}", out)

    def test_a_missing_file_is_a_cad_error(self):
        with self.assertRaises(isoflex.CadError):
            isoflex.cad_info("/nonexistent.igs")


if __name__ == "__main__":
    unittest.main()
