#!/usr/bin/env python3
"""Cross-check of our simulator against Basilisk (independent implementation), open loop.

Builds the servicer in Basilisk from the same URDF — a hub with the 7-DoF arm as a
`spinningBodyNDOFStateEffector`, every joint origin, axis and link inertial taken from the
parsed file — and the target as a second spacecraft, both on two-body orbits around a
point-mass Earth with the scenario's mu, RK4 at the scenario's physics step. Both
simulators start from the same state (row 0 of `safe-capture simulate`) and get the same
command profile (base force and torque in the base frame, joint torques; zero-order hold at
the control period); the script compares, at every control step, the servicer's base
position and attitude, the joint angles, the target's attitude and the Hill-frame relative
position, prints the largest differences and writes them per step.

Needs Basilisk (`scripts/setup.sh --with-basilisk`, pinned bsk in
scripts/requirements-basilisk.txt) and a release build of safe-capture.

Usage: scripts/basilisk_reference.py [--scenario config/scenario.toml] [--duration 30]
           [--safe-capture target/release/safe-capture] [--out out/basilisk_reference]

Conventions (see the shared notes): Basilisk's hub initial position/velocity is the
system's centre of mass, its outputs are the hub origin; attitudes are MRPs, compared as
rotation matrices; a command written before ExecuteSimulation acts on (t_k, t_k+1].
"""

import argparse
import csv
import json
import math
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

import tomllib

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def rel(path):
    return path if os.path.isabs(path) else os.path.join(ROOT, path)


# ---------------------------------------------------------------- URDF ----
def rpy_matrix(rpy):
    r, p, y = rpy
    cx, sx, cy, sy, cz, sz = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


def axis_angle(axis, angle):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -a[2], a[1]], [a[2], 0, -a[0]], [-a[1], a[0], 0]])
    return np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k


def vec(text, default="0 0 0"):
    return np.array([float(x) for x in (text or default).split()])


def parse_urdf(path):
    """The base's inertial and the revolute chain from the base outwards. Fixed joints
    between revolute joints are folded into the next revolute joint's origin."""
    root = ET.parse(path).getroot()
    links = {l.get("name"): l for l in root.findall("link")}
    joints = root.findall("joint")
    by_parent = {}
    for j in joints:
        by_parent.setdefault(j.find("parent").get("link"), []).append(j)
    parents = {j.find("child").get("link") for j in joints}
    base = [n for n in links if n not in parents]
    if len(base) != 1:
        raise SystemExit(f"{path}: expected one root link, found {base}")

    def inertial(link):
        el = links[link].find("inertial")
        if el is None:
            return 0.0, np.zeros(3), np.zeros((3, 3))
        o = el.find("origin")
        xyz = vec(o.get("xyz") if o is not None else None)
        rot = rpy_matrix(vec(o.get("rpy") if o is not None else None))
        i = el.find("inertia")
        g = lambda k: float(i.get(k, "0"))  # noqa: E731
        tensor = np.array([[g("ixx"), g("ixy"), g("ixz")], [g("ixy"), g("iyy"), g("iyz")], [g("ixz"), g("iyz"), g("izz")]])
        return float(el.find("mass").get("value")), xyz, rot @ tensor @ rot.T

    chain = []
    link, pending = base[0], (np.eye(3), np.zeros(3))
    while link in by_parent:
        j = by_parent[link][0] if len(by_parent[link]) == 1 else None
        if j is None:
            raise SystemExit(f"{path}: link {link} branches; a serial chain is expected")
        o = j.find("origin")
        r_o = rpy_matrix(vec(o.get("rpy") if o is not None else None))
        p_o = vec(o.get("xyz") if o is not None else None)
        rot, pos = pending[0] @ r_o, pending[0] @ p_o + pending[1]
        child = j.find("child").get("link")
        if j.get("type") == "revolute":
            m, com, inertia = inertial(child)
            chain.append(dict(name=j.get("name"), rot=rot, pos=pos, axis=vec(j.find("axis").get("xyz")), mass=m, com=com, inertia=inertia))
            pending = (np.eye(3), np.zeros(3))
        elif j.get("type") == "fixed":
            pending = (rot, pos)
            if inertial(child)[0] > 0:
                raise SystemExit(f"{path}: fixed link {child} has mass; not supported here")
        else:
            raise SystemExit(f"{path}: joint type {j.get('type')} not supported")
        link = child
    return dict(base=inertial(base[0]), chain=chain)


def com_offset(model, theta, theta_dot):
    """System CoM and its body-frame rate of change w.r.t. the base origin, in the base frame."""
    m0, c0, _ = model["base"]
    rot, pos = np.eye(3), np.zeros(3)
    omega, vel = np.zeros(3), np.zeros(3)  # link frame's angular velocity and origin velocity
    total, moment, moment_dot = m0, m0 * c0, np.zeros(3)
    for b, th, thd in zip(model["chain"], theta, theta_dot):
        new_pos = pos + rot @ b["pos"]
        vel = vel + np.cross(omega, rot @ b["pos"])
        rot = rot @ b["rot"] @ axis_angle(b["axis"], th)
        omega = omega + rot @ (b["axis"] / np.linalg.norm(b["axis"])) * thd
        pos = new_pos
        c = pos + rot @ b["com"]
        total += b["mass"]
        moment += b["mass"] * c
        moment_dot += b["mass"] * (vel + np.cross(omega, rot @ b["com"]))
    return moment / total, moment_dot / total


# Largest differences accepted over the default 30 s (measured: 1.5e-8 m, 2.6e-13 rad,
# 2.1e-10 rad, 1.1e-14 rad — the inertial positions are 7e6 m numbers, so 1e-8 m is a few
# of their last digits). Beyond ~35 s the open-loop arm's motion turns chaotic and the two
# simulators part (40 s: joints 1.9e-8 rad), as any two exact integrators would.
TOLERANCE = dict(base_position_m=1e-6, base_attitude_rad=1e-9, joint_angle_rad=1e-8,
                 target_attitude_rad=1e-12, hill_position_m=1e-6)


# ---------------------------------------------------------- rotations ----
def quat_to_dcm(q):
    """Rotation matrix of the scalar-first unit quaternion q (rotates the body's vectors
    into the frame the quaternion is relative to)."""
    w, x, y, z = q / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def angle_between(r1, r2):
    """The angle of the rotation r1ᵀ r2, accurate for small angles too."""
    m = r1.T @ r2
    v = np.array([m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]]) / 2
    return math.atan2(np.linalg.norm(v), (np.trace(m) - 1) / 2)


def hill_position(r_s, r_t, v_t):
    """Servicer position relative to the target in the target's Hill frame (R, V, H)."""
    x = r_t / np.linalg.norm(r_t)
    h = np.cross(r_t, v_t)
    z = h / np.linalg.norm(h)
    y = np.cross(z, x)
    return np.array([x, y, z]) @ (r_s - r_t)


# ------------------------------------------------------------ profile ----
# Joint-torque amplitudes, smaller towards the light wrist: the arm moves by tenths of a
# radian instead of spinning, so the open-loop comparison stays out of the chaotic regime
# for longer.
JOINT_TORQUE_AMPLITUDE_NM = [0.05, 0.05, 0.03, 0.03, 0.01, 0.01, 0.004]


def write_profile(path, duration, dt):
    """A smooth, non-resonant test profile well inside the actuator bounds."""
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t_s", "f_b_x_n", "f_b_y_n", "f_b_z_n", "tau_b_x_nm", "tau_b_y_nm", "tau_b_z_nm"] + [f"tau_m_{i}_nm" for i in range(1, 8)])
        for k in range(int(round(duration / dt)) + 1):
            t = k * dt
            f = [2.0 * math.sin(0.21 * t), 1.5 * math.cos(0.17 * t), -1.0 * math.sin(0.13 * t + 0.4)]
            tau = [0.8 * math.sin(0.11 * t), -0.6 * math.sin(0.23 * t + 1.0), 0.5 * math.cos(0.19 * t)]
            tm = [a * math.sin((0.3 + 0.07 * i) * t + i) for i, a in enumerate(JOINT_TORQUE_AMPLITUDE_NM)]
            w.writerow([repr(t)] + [repr(x) for x in f + tau + tm])


# ----------------------------------------------------------- Basilisk ----
class BasiliskModel:
    """The servicer (hub + arm) and the target in Basilisk, from the initial state `x` (dict:
    servicer base origin r_b, v_b [inertial], q_ib, w_b, theta, theta_dot; target CoM r_t,
    v_t, q_it, w_t; quaternions scalar first) — shared by this cross-check and the plant of
    `safe-capture run --basilisk` (scripts/basilisk_plant.py). `add_to(sim, task)` puts the
    models in a task in the order that makes the arm integrate this step's torques;
    `command(u)` writes a 13-vector [f_B, tau_B, tau_M] for the next step."""

    def __init__(self, scenario, model, x):
        from Basilisk.architecture import messaging
        from Basilisk.simulation import extForceTorque, spacecraft, spinningBodyNDOFStateEffector, svIntegrators
        from Basilisk.utilities import RigidBodyKinematics as rbk
        from Basilisk.utilities import simIncludeGravBody

        self.messaging, self.rbk = messaging, rbk
        grav = simIncludeGravBody.gravBodyFactory()
        earth = grav.createEarth()
        earth.isCentralBody = True
        earth.mu = scenario["orbit"]["earth_mu_m3_s2"]

        # servicer: hub + arm
        sc = spacecraft.Spacecraft()
        sc.ModelTag = "servicer"
        m0, c0, i0 = model["base"]
        sc.hub.mHub = m0
        sc.hub.r_BcB_B = c0.reshape(3, 1).tolist()
        sc.hub.IHubPntBc_B = i0.tolist()
        arm = spinningBodyNDOFStateEffector.SpinningBodyNDOFStateEffector()
        arm.ModelTag = "arm"
        for b, th, thd in zip(model["chain"], x["theta"], x["theta_dot"]):
            s = spinningBodyNDOFStateEffector.SpinningBody()
            s.setMass(b["mass"])
            s.setISPntSc_S(b["inertia"].tolist())
            s.setDCM_S0P(b["rot"].T.tolist())
            s.setR_ScS_S(b["com"].reshape(3, 1).tolist())
            s.setR_SP_P(b["pos"].reshape(3, 1).tolist())
            s.setSHat_S((b["axis"] / np.linalg.norm(b["axis"])).reshape(3, 1).tolist())
            s.setThetaInit(float(th))
            s.setThetaDotInit(float(thd))
            arm.addSpinningBody(s)
        sc.addStateEffector(arm)
        ext = extForceTorque.ExtForceTorque()
        ext.ModelTag = "wrench"
        sc.addDynamicEffector(ext)
        self.torque_msg = messaging.ArrayMotorTorqueMsg()
        arm.motorTorqueInMsg.subscribeTo(self.torque_msg)

        # the hub's initial position and velocity are the system's centre of mass
        r_ib = quat_to_dcm(x["q_ib"])
        c_b, c_dot_b = com_offset(model, x["theta"], x["theta_dot"])
        sc.hub.r_CN_NInit = (x["r_b"] + r_ib @ c_b).reshape(3, 1).tolist()
        sc.hub.v_CN_NInit = (x["v_b"] + r_ib @ (np.cross(x["w_b"], c_b) + c_dot_b)).reshape(3, 1).tolist()
        sc.hub.sigma_BNInit = np.array(rbk.C2MRP(r_ib.T)).reshape(3, 1).tolist()
        sc.hub.omega_BN_BInit = np.asarray(x["w_b"]).reshape(3, 1).tolist()
        sc.setIntegrator(svIntegrators.svIntegratorRK4(sc))
        grav.addBodiesTo(sc)

        # target: a torque-free rigid body
        tg = spacecraft.Spacecraft()
        tg.ModelTag = "target"
        tg.hub.mHub = scenario["target"]["mass_kg"]
        tg.hub.IHubPntBc_B = scenario["target"]["inertia_kg_m2"]
        tg.hub.r_BcB_B = [[0.0], [0.0], [0.0]]
        tg.hub.r_CN_NInit = np.asarray(x["r_t"]).reshape(3, 1).tolist()
        tg.hub.v_CN_NInit = np.asarray(x["v_t"]).reshape(3, 1).tolist()
        tg.hub.sigma_BNInit = np.array(rbk.C2MRP(quat_to_dcm(x["q_it"]).T)).reshape(3, 1).tolist()
        tg.hub.omega_BN_BInit = np.asarray(x["w_t"]).reshape(3, 1).tolist()
        tg.setIntegrator(svIntegrators.svIntegratorRK4(tg))
        grav.addBodiesTo(tg)
        self.sc, self.tg, self.arm, self.ext = sc, tg, arm, ext

    def add_to(self, sim, task):
        # the arm reads the motor torques before the spacecraft integrate with them (its output
        # message would then be a physics step old: the joint states are read from the states)
        for m, priority in ((self.arm, 300), (self.ext, 300), (self.sc, 200), (self.tg, 200)):
            sim.AddModelToTask(task, m, None, priority)

    def joint_states(self):
        """The arm's theta and thetaDot state objects (after InitializeSimulation)."""
        dm = self.sc.dynManager
        return dm.getStateObject(self.arm.getNameOfThetaState()), dm.getStateObject(self.arm.getNameOfThetaDotState())

    def command(self, u):
        self.ext.extForce_B = [[u[0]], [u[1]], [u[2]]]
        self.ext.extTorquePntB_B = [[u[3]], [u[4]], [u[5]]]
        p = self.messaging.ArrayMotorTorqueMsgPayload()
        p.motorTorque = list(u[6:13])
        self.torque_msg.write(p)


def run_basilisk(scenario, model, ours, profile, dt_ctrl, dt_phys, steps):
    from Basilisk.utilities import SimulationBaseClass, macros

    row0 = ours[0]
    col = lambda stem, axes: np.array([row0[f"{stem}{a}"] for a in axes])  # noqa: E731
    x = dict(
        theta=col("theta_", [f"{i}_rad" for i in range(1, 8)]),
        theta_dot=col("theta_dot_", [f"{i}_rad_s" for i in range(1, 8)]),
        q_ib=col("servicer_q", ["0_ib", "1_ib", "2_ib", "3_ib"]),
        w_b=col("servicer_w", ["x_b_rad_s", "y_b_rad_s", "z_b_rad_s"]),
        r_b=col("servicer_", ["x_i_m", "y_i_m", "z_i_m"]),
        v_b=col("servicer_v", ["x_i_m_s", "y_i_m_s", "z_i_m_s"]),
        q_it=col("target_q", ["0_it", "1_it", "2_it", "3_it"]),
        r_t=col("target_", ["x_i_m", "y_i_m", "z_i_m"]),
        v_t=col("target_v", ["x_i_m_s", "y_i_m_s", "z_i_m_s"]),
        w_t=col("target_w", ["x_t_rad_s", "y_t_rad_s", "z_t_rad_s"]),
    )
    sim = SimulationBaseClass.SimBaseClass()
    proc = sim.CreateNewProcess("dynamics")
    proc.addTask(sim.CreateNewTask("step", macros.sec2nano(dt_phys)))
    bm = BasiliskModel(scenario, model, x)
    bm.add_to(sim, "step")
    sim.InitializeSimulation()
    theta_state, _ = bm.joint_states()
    rbk = bm.rbk

    rows = []
    for k in range(steps + 1):
        s = bm.sc.scStateOutMsg.read()
        t = bm.tg.scStateOutMsg.read()
        rows.append(dict(
            r_b=np.array(s.r_BN_N), v_b=np.array(s.v_BN_N), c_bn=np.array(rbk.MRP2C(s.sigma_BN)),
            r_t=np.array(t.r_BN_N), v_t=np.array(t.v_BN_N), c_tn=np.array(rbk.MRP2C(t.sigma_BN)),
            theta=np.array(theta_state.getState()).flatten(),
        ))
        if k == steps:
            break
        bm.command(profile[k])
        sim.ConfigureStopTime(macros.sec2nano((k + 1) * dt_ctrl))
        sim.ExecuteSimulation()
    return rows


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--scenario", default="config/scenario.toml")
    ap.add_argument("--duration", type=float, default=30.0, help="seconds (open loop: the arm's motion is chaotic beyond ~50 s)")
    ap.add_argument("--safe-capture", default="target/release/safe-capture")
    ap.add_argument("--out", default="out/basilisk_reference")
    a = ap.parse_args()
    scenario_path = rel(a.scenario)
    with open(scenario_path, "rb") as f:
        scenario = tomllib.load(f)
    dt_ctrl = scenario["mission"]["control_period_s"]
    dt_phys = scenario["mission"]["physics_step_s"]
    steps = int(round(a.duration / dt_ctrl))
    out = rel(a.out)
    os.makedirs(out, exist_ok=True)
    urdf = os.path.join(os.path.dirname(scenario_path), scenario["servicer"]["urdf"])
    model = parse_urdf(urdf)

    profile_path = os.path.join(out, "profile.csv")
    write_profile(profile_path, a.duration, dt_ctrl)
    traj_path = os.path.join(out, "ours.csv")
    subprocess.run([rel(a.safe_capture), "simulate", "--scenario", scenario_path, "--commands", profile_path,
                    "--out", traj_path, "--duration", repr(a.duration)], check=True)
    with open(traj_path) as f:
        ours = [{k: float(v) for k, v in r.items()} for r in csv.DictReader(f)]
    with open(profile_path) as f:
        profile = [[float(x) for x in r[1:]] for r in list(csv.reader(f))[1:]]

    bsk = run_basilisk(scenario, model, ours, profile, dt_ctrl, dt_phys, steps)

    worst = dict(base_position_m=0.0, base_attitude_rad=0.0, joint_angle_rad=0.0, target_attitude_rad=0.0, hill_position_m=0.0)
    with open(os.path.join(out, "differences.csv"), "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["t_s"] + list(worst))
        for o, b in zip(ours, bsk):
            g = lambda stem, axes: np.array([o[f"{stem}{x}"] for x in axes])  # noqa: E731
            r_b = g("servicer_", ["x_i_m", "y_i_m", "z_i_m"])
            r_t = g("target_", ["x_i_m", "y_i_m", "z_i_m"])
            v_t = g("target_v", ["x_i_m_s", "y_i_m_s", "z_i_m_s"])
            c_ib = quat_to_dcm(g("servicer_q", ["0_ib", "1_ib", "2_ib", "3_ib"]))
            c_it = quat_to_dcm(g("target_q", ["0_it", "1_it", "2_it", "3_it"]))
            theta = g("theta_", [f"{i}_rad" for i in range(1, 8)])
            d = dict(
                base_position_m=float(np.linalg.norm(r_b - b["r_b"])),
                base_attitude_rad=angle_between(c_ib.T, b["c_bn"]),
                joint_angle_rad=float(np.abs(theta - b["theta"]).max()),
                target_attitude_rad=angle_between(c_it.T, b["c_tn"]),
                hill_position_m=float(np.linalg.norm(hill_position(r_b, r_t, v_t) - hill_position(b["r_b"], b["r_t"], b["v_t"]))),
            )
            for k, v in d.items():
                worst[k] = max(worst[k], v)
            w.writerow([o["t_s"]] + [repr(v) for v in d.values()])
    exceeded = {k: v for k, v in worst.items() if not v <= TOLERANCE[k]}
    with open(os.path.join(out, "summary.json"), "w") as f:
        json.dump(dict(duration_s=a.duration, steps=steps, worst=worst, tolerance=TOLERANCE, exceeded=sorted(exceeded)), f, indent=2)
    print("basilisk_reference: over %.1f s (%d control steps), largest differences: %s; %s -> %s" % (
        a.duration, steps, ", ".join(f"{k} {v:.3e}" for k, v in worst.items()),
        "within the tolerances" if not exceeded else "EXCEEDED: " + ", ".join(sorted(exceeded)), out))
    return 1 if exceeded else 0


if __name__ == "__main__":
    sys.exit(main())
