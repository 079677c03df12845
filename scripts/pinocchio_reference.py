#!/usr/bin/env python3
"""Reference data for sc-multibody from Pinocchio (independent implementation).

Builds the servicer URDF as a free-flyer (pin.JointModelFreeFlyer, gravity zero) and writes,
for random states, the quantities that libs/multibody/tests/pinocchio.rs compares:

  mass matrix (symmetrized crba), nonLinearEffects, aba, EE pose + 6x7 Jacobian + J̇θ̇ in the
  BASE frame, every collision-sphere centre (pin.buildGeomFromUrdf) + 3x7 Jacobian + J̇θ̇ in the
  base frame, system CoM / linear momentum / angular momentum about the CoM (base frame),
  kinetic energy, and the fixed-base arm M(θ), C(θ,θ̇)θ̇.

Conventions (see shared notes): q = [p (world), quat x y z w, θ]; v = [v_B (base frame),
ω_B (base frame), θ̇]; tau = [f_B, τ_B (base frame, at/about the base origin), τ_M].

Usage: scripts/pinocchio_reference.py [--urdf config/servicer.urdf]
           [--out tests/reference/pinocchio_reference.generated.json] [--states 60] [--seed N]
"""

import argparse
import json
import os
import sys

import numpy as np
import pinocchio as pin

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def rel(path):
    return path if os.path.isabs(path) else os.path.join(ROOT, path)


def base_frame_jacobian(model, data, frame_id, R):
    """Joint columns of the frame Jacobian, expressed in the base frame.

    LOCAL_WORLD_ALIGNED gives [linear velocity of the frame origin; angular velocity] in world
    axes; with the base held fixed, the base-frame derivative of the relative position is
    R^T times that (R = base rotation)."""
    J = pin.getFrameJacobian(model, data, frame_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
    out = np.zeros((6, 7))
    out[:3, :] = R.T @ J[:3, 6:]
    out[3:, :] = R.T @ J[3:, 6:]
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--urdf", default="config/servicer.urdf")
    ap.add_argument("--out", default="tests/reference/pinocchio_reference.generated.json")
    ap.add_argument("--states", type=int, default=60)
    ap.add_argument("--seed", type=int, default=20240601)
    ap.add_argument("--extra-urdf", action="append", default=None,
                    help="further test models to include (default: libs/multibody/tests/data/generic_arm.urdf)")
    args = ap.parse_args()
    extra = args.extra_urdf if args.extra_urdf is not None else ["libs/multibody/tests/data/generic_arm.urdf"]

    out = generate(args.urdf, args.states, args.seed)
    out["generator"] = "scripts/pinocchio_reference.py"
    out["pinocchio_version"] = pin.__version__
    out["extra_models"] = [generate(e, max(20, args.states // 2), args.seed + 1 + i) for i, e in enumerate(extra)]
    path = rel(args.out)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "w") as fh:
        json.dump(out, fh, indent=1)
    print(f"wrote {len(out['states'])} states (+{len(extra)} extra models) to {path} (pinocchio {pin.__version__})", file=sys.stderr)


def generate(urdf_arg, n_states, seed):
    """Reference quantities for one URDF."""
    urdf = rel(urdf_arg)
    model = pin.buildModelFromUrdf(urdf, pin.JointModelFreeFlyer())
    model.gravity = pin.Motion.Zero()
    data = model.createData()
    geom = pin.buildGeomFromUrdf(model, urdf, pin.GeometryType.COLLISION)

    # Fixed-base model: world = base frame, used for M(θ), Cθ̇ and the J̇θ̇ drift terms.
    fmodel = pin.buildModelFromUrdf(urdf)
    fmodel.gravity = pin.Motion.Zero()
    fgeom = pin.buildGeomFromUrdf(fmodel, urdf, pin.GeometryType.COLLISION)

    assert model.nq == 7 + 7 and model.nv == 13, (model.nq, model.nv)
    root_id = model.getJointId("root_joint")
    ee_id = model.getFrameId("end_effector")
    fee_id = fmodel.getFrameId("end_effector")

    # Collision spheres: name "<link>_<k>" (k = index among the link's <collision> elements).
    spheres = []
    for go, fgo in zip(geom.geometryObjects, fgeom.geometryObjects):
        assert go.name == fgo.name
        radius = float(go.geometry.radius)  # coal.Sphere
        link, k = go.name.rsplit("_", 1)
        # Attach an operational frame at the sphere centre (both models) for Jacobians/drifts.
        fid = model.addFrame(pin.Frame("sph_" + go.name, go.parentJoint, go.parentFrame, go.placement, pin.FrameType.OP_FRAME))
        ffid = fmodel.addFrame(pin.Frame("sph_" + go.name, fgo.parentJoint, fgo.parentFrame, fgo.placement, pin.FrameType.OP_FRAME))
        spheres.append((link, int(k), radius, fid, ffid))
    data = model.createData()
    fdata = fmodel.createData()

    lower = fmodel.lowerPositionLimit
    upper = fmodel.upperPositionLimit
    vlim = fmodel.velocityLimit
    rng = np.random.default_rng(seed)
    states = []
    for s in range(n_states):
        pos = rng.uniform(-5.0, 5.0, 3)
        quat = rng.normal(size=4)
        quat /= np.linalg.norm(quat)  # x y z w
        theta = rng.uniform(lower, upper)
        v_lin = rng.uniform(-0.2, 0.2, 3)
        omega = rng.uniform(-0.2, 0.2, 3)
        theta_dot = rng.uniform(-1.5 * vlim, 1.5 * vlim)
        f_b = rng.uniform(-7.0, 7.0, 3)
        tau_b = rng.uniform(-10.0, 10.0, 3)
        tau_m = rng.uniform(-2.0, 2.0, 7)
        if s == 0:  # one state at rest in the reference configuration
            pos[:] = 0.0
            quat = np.array([0.0, 0.0, 0.0, 1.0])
            theta[:] = 0.0
            v_lin[:] = 0.0
            omega[:] = 0.0
            theta_dot[:] = 0.0
        q = np.concatenate([pos, quat, theta])
        v = np.concatenate([v_lin, omega, theta_dot])
        u = np.concatenate([f_b, tau_b, tau_m])

        M = pin.crba(model, data, q)
        M = np.triu(M) + np.triu(M, 1).T
        b = pin.nonLinearEffects(model, data, q, v)
        a = pin.aba(model, data, q, v, u)
        # Cross-check: aba == M^-1 (u - b)
        assert np.allclose(a, np.linalg.solve(M, u - b), rtol=1e-9, atol=1e-10)

        pin.forwardKinematics(model, data, q, v)
        pin.updateFramePlacements(model, data)
        pin.computeJointJacobians(model, data, q)
        oMb = data.oMi[root_id]
        R = oMb.rotation
        bMee = oMb.actInv(data.oMf[ee_id])
        J_ee = base_frame_jacobian(model, data, ee_id, R)

        # System CoM, momentum, energy (world -> base frame).
        com_w = pin.centerOfMass(model, data, q, v)
        hg = pin.computeCentroidalMomentum(model, data, q, v)
        ke = pin.computeKineticEnergy(model, data, q, v)
        com_b = R.T @ (com_w - oMb.translation)

        # Fixed-base quantities (world frame of fmodel == base frame).
        fM = pin.crba(fmodel, fdata, theta)
        fM = np.triu(fM) + np.triu(fM, 1).T
        fC = pin.nonLinearEffects(fmodel, fdata, theta, theta_dot)
        pin.forwardKinematics(fmodel, fdata, theta, theta_dot, np.zeros(7))
        pin.updateFramePlacements(fmodel, fdata)
        pin.computeJointJacobians(fmodel, fdata, theta)
        fee_acc = pin.getFrameClassicalAcceleration(fmodel, fdata, fee_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        fJ_ee = pin.getFrameJacobian(fmodel, fdata, fee_id, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
        assert np.allclose(fJ_ee, J_ee, atol=1e-12)
        assert np.allclose(fdata.oMf[fee_id].translation, bMee.translation, atol=1e-12)

        sph = []
        for link, k, radius, fid, ffid in spheres:
            bMs = oMb.actInv(data.oMf[fid])
            Js = base_frame_jacobian(model, data, fid, R)
            acc = pin.getFrameClassicalAcceleration(fmodel, fdata, ffid, pin.ReferenceFrame.LOCAL_WORLD_ALIGNED)
            assert np.allclose(fdata.oMf[ffid].translation, bMs.translation, atol=1e-12)
            sph.append({
                "link": link,
                "index": k,
                "radius": radius,
                "center": bMs.translation.tolist(),
                "jacobian": Js[:3, :].tolist(),
                "jdot_qdot": acc.linear.tolist(),
            })

        states.append({
            "q": q.tolist(),
            "v": v.tolist(),
            "u": u.tolist(),
            "theta": theta.tolist(),
            "theta_dot": theta_dot.tolist(),
            "mass_matrix": M.tolist(),
            "bias": b.tolist(),
            "aba": a.tolist(),
            "ee_position": bMee.translation.tolist(),
            "ee_rotation": bMee.rotation.tolist(),
            "ee_jacobian": J_ee.tolist(),
            "ee_jdot_qdot": np.concatenate([fee_acc.linear, fee_acc.angular]).tolist(),
            "com": com_b.tolist(),
            "linear_momentum": (R.T @ hg.linear).tolist(),
            "angular_momentum_com": (R.T @ hg.angular).tolist(),
            "kinetic_energy": float(ke),
            "arm_mass_matrix": fM.tolist(),
            "arm_coriolis": fC.tolist(),
            "spheres": sph,
        })

    return {
        "urdf": urdf_arg,
        "seed": seed,
        "total_mass": float(sum(I.mass for I in model.inertias)),
        "states": states,
    }

if __name__ == "__main__":
    main()
