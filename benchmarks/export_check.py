"""Does the exported URDF of a run reproduce its solution? Loads RUN/export/best.urdf in pinocchio (which knows
nothing of designopt) and prints, over every waypoint of RUN/best.json, the largest difference between
pinocchio's pose of ``designopt_tool`` (or ``tool`` for a DH robot) and designopt's tool pose, with the joint
names the file uses. Continuous joints are (cos, sin) in pinocchio; joints off the chain (fingers) stay neutral.

    .venv/bin/python benchmarks/export_check.py results/panda_button/RUN1
"""

from __future__ import annotations

import argparse
import json
import signal
from pathlib import Path

import numpy as np
import pinocchio as pin

from designopt.export import joint_names
from designopt.kinematics.chain import tool_pose
from designopt.solution import chain_from_file


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run", type=Path, help="a run directory written with --urdf")
    args = parser.parse_args()
    best = json.loads((args.run / "best.json").read_text())
    model = pin.buildModelFromUrdf(str(args.run / "export" / "best.urdf"))
    data, names, chain = model.createData(), joint_names(best), chain_from_file(best)
    frame = model.getFrameId("designopt_tool" if model.existFrame("designopt_tool") else "tool")
    worst = 0.0
    for q in best["q"]:
        q, config = np.array(q), pin.neutral(model)
        for name, value in zip(names, q, strict=True):
            joint = model.joints[model.getJointId(name)]
            config[joint.idx_q: joint.idx_q + joint.nq] = [np.cos(value), np.sin(value)] if joint.nq == 2 else value
        pin.framesForwardKinematics(model, data, config)
        worst = max(worst, float(np.abs(data.oMf[frame].homogeneous - tool_pose(chain, q, np.zeros(0))).max()))
    print(f"{args.run}: {len(best['q'])} waypoints, joints {', '.join(names)}; "
          f"max |pinocchio - designopt| over the tool pose = {worst:.2e}")


if __name__ == "__main__":
    signal.signal(signal.SIGPIPE, signal.SIG_DFL)  # piped into head: stop quietly
    main()
