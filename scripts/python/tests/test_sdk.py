"""Unit tests of the partner SDK's pure-Python parts (no partition, no iceoryx2 process).

Run: ``PYTHONPATH=scripts/python python -m unittest discover -s scripts/python/tests``
(``apps/partition/tests/python_sdk.rs`` does).
"""

import math
import struct
import unittest

import numpy as np

from sc_partner import Measurement, Navigation, NominalController, State, icd
from sc_partner import mcap
from sc_partner.config import group_periods, phase_index
from sc_partner.harness import quaternion_from_matrix, rotation_between


def rotation_matrix(q):
    """R(q) of a scalar-first unit quaternion, column by column through icd.rotate."""
    return np.column_stack([icd.rotate(q, e) for e in np.eye(3)])


class Rotations(unittest.TestCase):
    def test_quaternion_round_trip(self):
        rng = np.random.default_rng(7)
        for _ in range(200):
            q = rng.normal(size=4)
            q /= np.linalg.norm(q)
            q = -q if q[0] < 0 else q
            back = quaternion_from_matrix(rotation_matrix(q))
            self.assertLess(np.max(np.abs(back - q)), 1e-12)

    def test_triad_recovers_the_rotation_from_two_vector_pairs(self):
        rng = np.random.default_rng(3)
        q = rng.normal(size=4)
        q /= np.linalg.norm(q)
        r = rotation_matrix(q)
        a, b = rng.normal(size=3) * 10.0, rng.normal(size=3) * 10.0
        est = rotation_between(a, b, r @ a, r @ b)
        self.assertLess(np.max(np.abs(est - r)), 1e-13)


class Navigations(unittest.TestCase):
    class Nav(Navigation):
        def __init__(self, behaviour):
            self.behaviour = behaviour

        def estimate(self, m):
            if self.behaviour == "raise":
                raise ValueError("deliberate")
            if self.behaviour == "none":
                return None
            if self.behaviour == "list":
                return [1.0, 2.0]
            e = m.estimate()
            e.r_i[0] += 0.5
            e.tick = m.tick + 1
            return e

    def measurement(self):
        raw = icd.NavState(tick=7, t=0.7, measured_t=0.6)
        raw.r_i[:] = [1.0, 2.0, 3.0]
        raw.q_ib[:] = [1.0, 0.0, 0.0, 0.0]
        return raw

    def test_a_measurement_is_read_only_and_its_estimate_a_writable_copy(self):
        raw = self.measurement()
        m = Measurement(raw)
        with self.assertRaises(ValueError):
            m.r_i[0] = 5.0
        msg, reason = self.Nav("edit").message(raw)
        self.assertIsNone(reason)
        self.assertEqual((msg.tick, msg.t, msg.measured_t), (8, 0.7, 0.6))
        self.assertEqual(list(msg.r_i), [1.5, 2.0, 3.0])
        self.assertEqual(list(raw.r_i), [1.0, 2.0, 3.0], "the measurement itself is unchanged")

    def test_no_estimate_answers_the_labels_with_nan_and_says_why(self):
        for behaviour, why in [
            ("raise", "ValueError: deliberate"),
            ("none", "no estimate"),
            ("list", "not an Estimate"),
        ]:
            msg, reason = self.Nav(behaviour).message(self.measurement())
            self.assertEqual((msg.tick, msg.t, msg.measured_t), (7, 0.7, 0.6), behaviour)
            self.assertTrue(all(math.isnan(x) for x in msg.r_i), behaviour)
            self.assertTrue(all(math.isnan(x) for x in msg.q_ib), behaviour)
            self.assertIn(why, reason)


class Controllers(unittest.TestCase):
    class Echo(NominalController):
        subsystem = "attitude"

        def __init__(self, output):
            self.output = output

        def step(self, state):
            if isinstance(self.output, Exception):
                raise self.output
            return self.output

    def state(self, tick=4, due=icd.DUE_ATTITUDE):
        raw = icd.SimState(tick=tick, t=0.4, due_mask=due)
        raw.r_h[:] = [1.0, 2.0, 3.0]
        return State(raw, 1)

    def test_state_fields_are_read_only_arrays_and_numbers(self):
        s = self.state()
        self.assertEqual((s.tick, s.t, s.phase), (4, 0.4, 1))
        np.testing.assert_array_equal(s.r_h, [1.0, 2.0, 3.0])
        self.assertEqual(s.theta.shape, (icd.N_JOINTS,))
        with self.assertRaises(ValueError):
            s.r_h[0] = 5.0
        with self.assertRaises(AttributeError):
            s.no_such_field

    def test_valid_command_and_message(self):
        c = self.Echo([0.1, -0.2, 0.3])
        values, reason = c.command(self.state())
        self.assertIsNone(reason)
        msg, reason = c.message(self.state(), recv_ns=9)
        self.assertIsNone(reason)
        self.assertEqual((msg.tick, msg.valid, msg.phase, msg.recv_ns), (4, 1, 1, 9))
        self.assertEqual(list(msg.tau_b), [0.1, -0.2, 0.3])
        self.assertEqual(msg.type_name(), icd.NominalAttitude.type_name())

    def test_invalid_commands_publish_valid_zero(self):
        for output, why in [
            (None, "step returned None"),
            ([1.0, 2.0], "step returned shape (2,), the attitude command is 3 values (shape (3,))"),
            # a column vector is not a command: which of its axes is meant is a guess
            (np.zeros((3, 1)), "step returned shape (3, 1), the attitude command is 3 values"),
            ([1.0, math.nan, 0.0], "non-finite"),
            ("abc", "not numbers"),
            (RuntimeError("boom"), "step raised RuntimeError: boom"),
        ]:
            msg, reason = self.Echo(output).message(self.state())
            self.assertEqual(msg.valid, 0, output)
            self.assertEqual(list(msg.tau_b), [0.0, 0.0, 0.0])
            # the first line is the reason the launcher's verdict quotes
            self.assertIn(why, reason.splitlines()[0])

    def test_due_follows_the_subsystem_bit(self):
        c = self.Echo([0.0] * 3)
        self.assertTrue(c.due(self.state(due=icd.DUE_TRANSLATIONAL | icd.DUE_ATTITUDE | icd.DUE_ROBOTIC)))
        self.assertFalse(c.due(self.state(due=icd.DUE_TRANSLATIONAL | icd.DUE_ROBOTIC)))

    def test_unknown_subsystem_is_refused(self):
        class Bad(NominalController):
            subsystem = "orbital"

        with self.assertRaises(ValueError):
            Bad().spec()


class Config(unittest.TestCase):
    def test_phase_index_and_group_periods(self):
        sc = {"mission": {"phases": [{"start_s": 0.0}, {"start_s": 60.0}, {"start_s": 120.0}]}}
        self.assertEqual([phase_index(sc, t) for t in (0.0, 59.9, 60.0 - 1e-10, 60.0, 200.0)], [0, 0, 1, 1, 2])
        part = {
            "rate_groups": [
                {"period_s": 0.2, "members": ["translational"]},
                {"period_s": 0.1, "members": ["attitude", "robotic"]},
            ]
        }
        self.assertEqual(group_periods(part, "translational"), (0.2, 0.1))
        self.assertEqual(group_periods(part, "robotic"), (0.1, 0.1))


class Lz4(unittest.TestCase):
    def frame(self, *blocks, raw_last=False):
        out = bytearray(struct.pack("<I", 0x184D2204)) + bytes([0x40 | 0x20, 0x40, 0x00])  # FLG, BD, HC
        for i, b in enumerate(blocks):
            size = len(b) | (0x80000000 if raw_last and i == len(blocks) - 1 else 0)
            out += struct.pack("<I", size) + b
        return bytes(out + struct.pack("<I", 0))

    def test_literals_matches_overlap_and_raw_blocks(self):
        # "abcabcabcabcX": 3 literals, then a match of 9 at offset 3 (overlapping), then "X"
        block = bytes([0x35]) + b"abc" + struct.pack("<H", 3) + bytes([0x10]) + b"X"
        self.assertEqual(mcap.lz4_frame(self.frame(block)), b"abcabcabcabcX")
        # a long literal run (length 15 + 255 + 5 = 275) and a raw second block
        text = bytes(range(256)) + b"0123456789abcdefghi"
        block = bytes([0xF0, 255, 5]) + text
        self.assertEqual(mcap.lz4_frame(self.frame(block, b"raw!", raw_last=True)), text + b"raw!")

    def test_bad_offset_is_refused(self):
        block = bytes([0x10]) + b"a" + struct.pack("<H", 5) + bytes([0x00])
        with self.assertRaises(ValueError):
            mcap.lz4_frame(self.frame(block))


if __name__ == "__main__":
    unittest.main()


class OfflineNavigation(unittest.TestCase):
    """The harness judges a navigation's answers as the partition would: an estimate that
    raises or returns None is a step without an estimate, even though the partition gets
    the refusable NaN answer."""

    def test_no_estimate_is_counted_and_left_blank(self):
        from sc_partner.harness import run_offline_navigation

        class Sometimes(Navigation):
            def estimate(self, m):
                if m.tick % 2:
                    return None
                return m.estimate()

        ms = []
        for k in range(4):
            raw = icd.NavState(tick=k, t=0.1 * k, measured_t=0.1 * k)
            raw.q_ib[:] = [1.0, 0.0, 0.0, 0.0]
            ms.append(raw)
        out = run_offline_navigation(Sometimes(), ms, {}, 0.1)
        self.assertEqual([e.valid for e in out], [1, 0, 1, 0])
        self.assertIsNone(out[1].estimate)
        self.assertIn("no estimate", out[1].reason)


class HarnessInputs(unittest.TestCase):
    """Every input error of the harness's command line is one line on stderr naming the
    file and the fix, exit 2 (it used to be a 12-15-line traceback)."""

    def run_harness(self, *argv):
        import contextlib
        import io

        from sc_partner import harness

        err = io.StringIO()
        with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
            code = harness.main(list(argv))
        return code, err.getvalue()

    def test_every_input_error_is_one_line(self):
        import os
        import tempfile

        ctl = "sc_partner.examples.nominal_translational"
        scenario = os.path.join(os.path.dirname(__file__), "..", "..", "..", "config", "scenario.toml")
        with tempfile.TemporaryDirectory() as d:
            rec = os.path.join(d, "recording.mcap")
            with open(rec, "wb") as f:
                f.write(b"\x89MCAP0\r\n")
            part = os.path.join(d, "partition.toml")
            with open(part, "w") as f:
                f.write('scenario = "scenario.toml"\n[[rate_groups]]\nname = "c"\nperiod_s = 0.1\nmembers = []\n')
            text = os.path.join(d, "notes.csv")
            with open(text, "w") as f:
                f.write("a,b\n1,2\n")
            cases = [
                ((ctl, "--telemetry", rec, "--scenario", scenario), "is an MCAP recording: give it with --mcap"),
                ((ctl, "--telemetry", text, "--scenario", part), "is a partition config, not a scenario"),
                ((ctl, "--telemetry", text, "--scenario", scenario), "notes.csv: not a safe-capture telemetry.csv"),
                ((ctl, "--telemetry", os.path.join(d, "none.csv"), "--scenario", scenario), "none.csv: no such file"),
                ((ctl + ":Nope", "--telemetry", text, "--config", part), "has no attribute 'Nope'"),
                (("no_such_module:X", "--telemetry", text, "--config", part), "no module 'no_such_module'"),
            ]
            for argv, why in cases:
                code, err = self.run_harness(*argv)
                self.assertEqual(code, 2, (argv, err))
                self.assertEqual(len(err.strip().splitlines()), 1, (argv, err))
                self.assertTrue(err.startswith("harness: "), err)
                self.assertIn(why, err)

    def test_the_partners_own_errors_keep_their_traceback(self):
        import os
        import tempfile

        scenario = os.path.join(os.path.dirname(__file__), "..", "..", "..", "config", "scenario.toml")
        with tempfile.TemporaryDirectory() as d:
            ctl = os.path.join(d, "ctl.py")
            with open(ctl, "w") as f:
                f.write(
                    "from sc_partner import NominalController\n\n\n"
                    "class C(NominalController):\n"
                    "    subsystem = 'translational'\n\n"
                    "    def __init__(self):\n"
                    "        raise KeyError('kp')\n"
                )
            text = os.path.join(d, "notes.csv")
            with open(text, "w") as f:
                f.write("a\n1\n")
            # not "not a recording": the partner's KeyError itself
            with self.assertRaises(KeyError):
                self.run_harness(ctl + ":C", "--telemetry", text, "--scenario", scenario)
            # a config without the subsystem's rate group is an input error: one line
            part = os.path.join(d, "partition.toml")
            with open(part, "w") as f:
                f.write(f'scenario = "{scenario}"\n[[rate_groups]]\nname = "c"\nperiod_s = 0.1\nmembers = ["attitude"]\n')
            code, err = self.run_harness(
                "sc_partner.examples.nominal_translational", "--telemetry", text, "--config", part
            )
            self.assertEqual(code, 2, err)
            self.assertEqual(len(err.strip().splitlines()), 1, err)
            self.assertIn("(--config)", err)
