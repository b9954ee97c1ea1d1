"""isoflex.Simulation: the same steps as `isoflex run`, state views, errors, signals, GIL."""
import math
import os
import signal
import threading
import time
import unittest

import numpy as np

import isoflex
from support import cli_history, example

SLIDER_CRANK = example("slider_crank_flexible", "model.yaml")
SCORDELIS_LO = example("scordelis_lo", "kl_shell.yaml")


def short(path, t_end, *sets):
    m = isoflex.Model(path).set("solver.t_end", t_end)
    for key, value in sets:
        m.set(key, value)
    return m


class SameAsTheTool(unittest.TestCase):
    def test_history_equals_history_csv_bit_for_bit(self):
        for formulation in ("reparametrized", "constrained"):
            with self.subTest(formulation=formulation):
                sim = isoflex.Simulation(
                    short(SLIDER_CRANK, 0.1, ("solver.formulation", formulation)))
                results = sim.run()
                csv = cli_history(SLIDER_CRANK, "solver.t_end=0.1",
                                  f"solver.formulation={formulation}")
                self.assertEqual(sorted(k for k in results if k != "probes"), sorted(csv))
                for column, values in csv.items():
                    self.assertEqual(list(results[column]), values, column)

    def test_static_solve_and_the_kl_displacement(self):
        sim = isoflex.Simulation(SCORDELIS_LO)
        self.assertTrue(sim.static)
        results = sim.solve()
        self.assertEqual(list(results["t"]), [0.0, 1.0])
        probe = sim.probes["ref"]["displacement"]
        # IGA-thesis §6.4.1.2 (shared/data/references.md): vertical displacement -0.3006 at the
        # midpoint of the free edge; this mesh is within 0.5 %.
        self.assertAlmostEqual(probe[1] / -0.3006, 1.0, delta=5e-3)
        # The probe sits at the patch's parameters (0, 0): the same point of the same surface.
        u = sim.kl_displacement("roof", [0.0], [0.0])
        self.assertEqual(u.shape, (1, 3))
        np.testing.assert_allclose(u[0], probe, rtol=0, atol=1e-12)
        with self.assertRaises(ValueError):
            sim.kl_displacement("roof", [2.0], [0.0])
        with self.assertRaises(ValueError):
            sim.kl_displacement("floor", [0.0], [0.0])
        with self.assertRaises(RuntimeError):  # a static model has no time steps
            sim.step()


class StateAndValues(unittest.TestCase):
    def test_state_views_follow_the_simulation_and_are_read_only(self):
        sim = isoflex.Simulation(short(SLIDER_CRANK, 0.02))
        q = sim.state.q
        self.assertEqual(q.shape, (sim.n,))
        self.assertFalse(q.flags.writeable)
        with self.assertRaises(ValueError):
            q[0] = 1.0
        before = q.copy()
        stats = sim.step()
        self.assertGreater(stats["iterations"], 0)
        self.assertEqual(sim.state.step, 1)
        self.assertAlmostEqual(sim.state.t, 0.01, places=15)
        self.assertFalse(np.array_equal(before, q))  # the view shows the new state
        self.assertTrue(np.array_equal(q, sim.state.q))

    def test_energies_momenta_probes_and_resultants(self):
        sim = isoflex.Simulation(short(SLIDER_CRANK, 0.03))
        sim.run()
        r = sim.results()
        e = sim.energies
        self.assertEqual(e["total"], r["total_energy"][-1])
        self.assertEqual(e["kinetic"] + e["potential"], e["total"])
        self.assertEqual(list(sim.momenta["linear"]), [r["px"][-1], r["py"][-1], r["pz"][-1]])
        self.assertEqual(sim.constraint_violation, r["constraint_violation"][-1])
        self.assertEqual(list(sim.probes["connection"]["position"]),
                         list(r["probes"]["connection"]["position"][-1]))
        self.assertEqual(r["probes"]["slider_end"]["velocity"].shape, (4, 3))
        res = sim.beam_resultants()
        self.assertEqual(res["crank"]["n"].shape, (20, 3))
        self.assertEqual(res["slider"]["m"].shape, (15, 3))
        self.assertTrue(np.all(np.isfinite(res["crank"]["m"])))

    def test_a_callback_after_every_step(self):
        sim = isoflex.Simulation(short(SLIDER_CRANK, 0.05))
        seen = []
        sim.run(callback=lambda: seen.append(sim.state.step))
        self.assertEqual(seen, [1, 2, 3, 4, 5])
        sim.run(t_end=0.08)
        self.assertEqual(sim.state.step, 8)
        self.assertEqual(len(sim.results()["t"]), 9)


class Failures(unittest.TestCase):
    def test_a_newton_failure_says_where_and_keeps_the_state(self):
        m = short(SLIDER_CRANK, 0.05, ("solver.max_iterations", 1),
                  ("solver.max_subdivisions", 0))
        sim = isoflex.Simulation(m)
        q0 = sim.state.q.copy()
        with self.assertRaises(isoflex.NewtonFailure) as c:
            sim.run()
        e = c.exception
        self.assertEqual(e.step, 1)
        self.assertAlmostEqual(e.time, 0.01, places=15)
        self.assertTrue(math.isfinite(e.residual) and e.residual > 0)
        self.assertIn("step 1", str(e))
        self.assertIsInstance(e, RuntimeError)
        self.assertEqual(sim.state.step, 0)
        self.assertTrue(np.array_equal(sim.state.q, q0))
        self.assertEqual(len(sim.results()["t"]), 1)

    def test_an_exception_in_the_callback_stops_the_run(self):
        sim = isoflex.Simulation(short(SLIDER_CRANK, 0.05))

        def stop():
            if sim.state.step == 2:
                raise StopIteration("enough")

        with self.assertRaises(StopIteration):
            sim.run(callback=stop)
        self.assertEqual(sim.state.step, 2)


class Threads(unittest.TestCase):
    def test_ctrl_c_stops_a_run_between_two_steps(self):
        sim = isoflex.Simulation(short(SLIDER_CRANK, 100.0))  # 10⁴ steps, several seconds
        timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
        timer.start()
        try:
            with self.assertRaises(KeyboardInterrupt):
                sim.run()
        finally:
            timer.cancel()
        steps = sim.state.step
        self.assertGreater(steps, 0)
        self.assertLess(steps, 10000)
        self.assertEqual(len(sim.results()["t"]), steps + 1)
        self.assertTrue(np.all(np.isfinite(sim.state.q)))
        sim.step()  # and it goes on from there
        self.assertEqual(sim.state.step, steps + 1)

    def test_the_gil_is_released_while_stepping(self):
        sim = isoflex.Simulation(short(SLIDER_CRANK, 2.0))
        count, stop = [0], threading.Event()

        def spin():
            while not stop.is_set():
                count[0] += 1
                time.sleep(0)

        t = threading.Thread(target=spin)
        t.start()
        try:
            start = count[0]
            sim.run()
            during = count[0] - start
        finally:
            stop.set()
            t.join()
        # 200 steps of ~0.2 ms (bench/slider_crank.md): a thread that never got the GIL would
        # have counted ~0
        self.assertGreater(during, 50)


if __name__ == "__main__":
    unittest.main()
