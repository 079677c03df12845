#!/usr/bin/env python3
"""Basilisk as the plant of `safe-capture run --basilisk`: propagates the true state.

The servicer is a Basilisk hub with the 7-DoF arm as a `spinningBodyNDOFStateEffector`,
built from the scenario's URDF (parsed, not re-typed: `basilisk_reference.parse_urdf`);
the target is a second, torque-free spacecraft; both on two-body orbits around a
point-mass Earth with the scenario's mu; Basilisk's RK4 at the physics step it is asked
for. Everything else of the mission — nominal controllers, safety filters, the barrier
monitor, telemetry — stays in the Rust process that started this one.

Protocol (one line per message on stdin/stdout; numbers in shortest round-trip form;
`safe-capture`'s `plant_process.rs` is the other side):
  init <41 numbers>      -> ready          (SimState: t, r_t, v_t, q_it, w_t, dr, dv, q_ib,
                                            w_b, theta, theta_dot; inertial frame, SI,
                                            quaternions scalar first)
  step <h> <n> <13 numbers: f_B, tau_B, tau_M>  -> n lines `state <41 numbers>`
  stop                   -> exit 0
Any failure is answered with `error <message>` and exit 1.

Conventions that bite (docs/SIMULATOR.md): Basilisk's hub initial position and velocity
are the system's centre of mass, its outputs the hub origin; attitudes are MRPs (converted
through rotation matrices); a command written before ExecuteSimulation acts on the whole
step; the arm is updated before the spacecraft so that it integrates this step's torques.
"""

import argparse
import math
import os
import sys
import tomllib

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from basilisk_reference import BasiliskModel, parse_urdf  # noqa: E402


def dcm_to_quat(m, previous):
    """Scalar-first unit quaternion of the rotation matrix m, the sign nearest `previous`."""
    tr = np.trace(m)
    if tr > 0:
        s = 2.0 * math.sqrt(1.0 + tr)
        q = np.array([0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s])
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2])
        q = np.array([(m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s])
    elif m[1, 1] > m[2, 2]:
        s = 2.0 * math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2])
        q = np.array([(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s])
    else:
        s = 2.0 * math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1])
        q = np.array([(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s])
    q /= np.linalg.norm(q)
    return -q if np.dot(q, previous) < 0 else q


class BasiliskPlant:
    def __init__(self, scenario_path):
        with open(scenario_path, "rb") as f:
            self.scenario = tomllib.load(f)
        urdf = self.scenario["servicer"]["urdf"]
        if not os.path.isabs(urdf):
            urdf = os.path.join(os.path.dirname(os.path.abspath(scenario_path)), urdf)
        self.model = parse_urdf(urdf)
        self.sim = None

    def init(self, x):
        from Basilisk.utilities import SimulationBaseClass

        t, r_t, v_t, q_it, w_t = x[0], x[1:4], x[4:7], x[7:11], x[11:14]
        dr, dv, q_ib, w_b, theta, theta_dot = x[14:17], x[17:20], x[20:24], x[24:27], x[27:34], x[34:41]
        if t != 0.0:
            raise ValueError("the plant starts at t = 0 only")
        self.q_it, self.q_ib = q_it, q_ib
        self.t_ns = 0
        self.sim = SimulationBaseClass.SimBaseClass()
        self.proc = self.sim.CreateNewProcess("dynamics")
        self.task_step_ns = None
        self.bm = BasiliskModel(self.scenario, self.model, dict(
            r_b=r_t + dr, v_b=v_t + dv, q_ib=q_ib, w_b=w_b, theta=theta, theta_dot=theta_dot,
            r_t=r_t, v_t=v_t, q_it=q_it, w_t=w_t))

    def _start_task(self, h_ns):
        """The task is created at the first step, when the physics step is known."""
        self.proc.addTask(self.sim.CreateNewTask("step", h_ns))
        self.bm.add_to(self.sim, "step")
        self.sim.InitializeSimulation()
        self.theta_state, self.theta_dot_state = self.bm.joint_states()
        self.task_step_ns = h_ns

    def state(self):
        rbk = self.bm.rbk
        s = self.bm.sc.scStateOutMsg.read()
        t = self.bm.tg.scStateOutMsg.read()
        r_b, v_b = np.array(s.r_BN_N), np.array(s.v_BN_N)
        r_t, v_t = np.array(t.r_BN_N), np.array(t.v_BN_N)
        self.q_ib = dcm_to_quat(np.array(rbk.MRP2C(s.sigma_BN)).T, self.q_ib)
        self.q_it = dcm_to_quat(np.array(rbk.MRP2C(t.sigma_BN)).T, self.q_it)
        theta = np.array(self.theta_state.getState()).flatten()
        theta_dot = np.array(self.theta_dot_state.getState()).flatten()
        return np.concatenate([[self.t_ns * 1e-9], r_t, v_t, self.q_it, np.array(t.omega_BN_B), r_b - r_t, v_b - v_t,
                               self.q_ib, np.array(s.omega_BN_B), theta, theta_dot])

    def step(self, h, n, u):
        h_ns = int(round(h * 1e9))
        if self.task_step_ns is None:
            self._start_task(h_ns)
        elif h_ns != self.task_step_ns:
            raise ValueError(f"physics step changed from {self.task_step_ns} ns to {h_ns} ns")
        self.bm.command(u)
        out = []
        for _ in range(n):
            self.t_ns += h_ns
            self.sim.ConfigureStopTime(self.t_ns)
            self.sim.ExecuteSimulation()
            out.append(self.state())
        return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenario", default="config/scenario.toml")
    a = ap.parse_args()
    out = sys.stdout
    try:
        plant = BasiliskPlant(a.scenario)
        for line in sys.stdin:
            word, *rest = line.split()
            if word == "init":
                x = np.array([float(v) for v in rest])
                if x.size != 41:
                    raise ValueError(f"init: {x.size} numbers, 41 expected")
                plant.init(x)
                out.write("ready\n")
            elif word == "step":
                h, n, u = float(rest[0]), int(rest[1]), [float(v) for v in rest[2:]]
                if len(u) != 13:
                    raise ValueError(f"step: {len(u)} command numbers, 13 expected")
                for x in plant.step(h, n, u):
                    out.write("state " + " ".join(repr(float(v)) for v in x) + "\n")
            elif word == "stop":
                return 0
            else:
                raise ValueError(f"unknown message `{word}`")
            out.flush()
    except Exception as e:  # reported to the Rust side, which ends the run
        out.write(f"error {type(e).__name__}: {e}\n".replace("\n", " ").rstrip() + "\n")
        out.flush()
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
