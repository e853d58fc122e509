"""Export a solved design as URDF (robot + workpiece cell) and its joint trajectory.

Built with yourdfpy from the solution file alone (schema designopt.solution/1). Each DH link i becomes an
actuated joint about/along z_{i-1} (revolute or prismatic) followed by a fixed joint carrying the rest of
the DH transform:
    R link: Rz(q) . [Tz(d) Tx(a) Rx(alpha)]          fixed origin xyz = (a, 0, d),            rpy = (alpha, 0, 0)
    P link: Tz(q) . [Rz(theta) Tx(a) Rx(alpha)]      fixed origin xyz = (a cos t, a sin t, 0), rpy = (alpha, 0, theta)
(Rz and Tz commute, so the P form equals Rz(theta) Tz(q) Tx(a) Rx(alpha).) The workpiece frame W hangs
off the base at the optimized placement T_BW = Trans(xyz) Rz(yaw) Ry(pitch) Rx(roll) -- URDF's own
rpy convention -- and carries the toolpath as small spheres.

A robot read from a URDF (the solution names its file in ``urdf``) is exported as that file: its own joint and
link names, limits, inertias and meshes (a relative mesh path made absolute, so that the exported file finds
it; ``package://`` paths as they were), with the solved values of any freed origin component; designopt adds the
tool frame under ``tool_link`` and the cell under the root link. Without the source file the chain is written from
its elementary transforms, its moving joints still named as in the URDF.
"""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import yaml

BASE, TOOL, WORKPIECE = "base", "tool", "workpiece"


def _origin(xyz, rpy) -> np.ndarray:
    from designopt.kinematics.transforms import rot_x, rot_y, rot_z

    T = rot_z(rpy[2]) @ rot_y(rpy[1]) @ rot_x(rpy[0])
    T[:3, 3] = xyz
    return T


def source_urdf(data: dict) -> Path | None:
    """The URDF file a solution's robot was read from, if the solution names one and it is still readable."""
    source = (data.get("urdf") or {}).get("file")
    return Path(source) if source and Path(source).is_file() else None


def joint_names(data: dict) -> list[str]:
    """The exported URDF's moving joints, base to tool: a URDF robot's own names, ``joint<i>`` for a DH robot."""
    if "dh" in data or not data.get("joint_limits"):
        return [f"joint{i + 1}" for i in range(len(data["structure"]))]
    return [lim["name"] for lim in data["joint_limits"]]


def urdf_model(data: dict, name: str = "designopt_cell", sphere_radius: float = 0.004):
    """A yourdfpy URDF of the solution's robot and cell (not yet written)."""
    import yourdfpy as y

    grey = y.Material(name="link", color=y.Color(rgba=np.array([0.3, 0.45, 0.7, 1.0])))
    source = source_urdf(data)
    if source is not None:
        from designopt.kinematics.urdf import root_link

        source_model = _source_model(data, source)
        robot = source_model.robot
        links, joints, materials = robot.links, robot.joints, robot.materials
        _cell(data, root_link(source_model), data["urdf"]["tool_link"], links, joints, materials, sphere_radius,
              prefix="designopt_")
        return y.URDF(robot=y.Robot(name=robot.name, links=links, joints=joints, materials=materials,
                                    transmission=robot.transmission, gazebo=robot.gazebo),
                      build_scene_graph=True, load_meshes=False, filename_handler=y.filename_handler_null)
    links = [y.Link(name=BASE, visuals=[y.Visual(geometry=y.Geometry(sphere=y.Sphere(0.03)), material=grey)])]
    joints = []
    parent = BASE
    limits = data.get("joint_limits") or [{} for _ in data["structure"]]
    if "dh" not in data:
        parent = _ets_robot(data, limits, links, joints, grey)
    for i, (row, lim) in enumerate(zip(data.get("dh", []), limits[: len(data.get("dh", []))], strict=True), start=1):
        moving, frame = f"link{i}_moving", f"frame{i}"
        lower = lim.get("lower", -2 * np.pi if row["type"] == "R" else -2.0)
        upper = lim.get("upper", 2 * np.pi if row["type"] == "R" else 2.0)
        joints.append(y.Joint(
            name=f"joint{i}", type="revolute" if row["type"] == "R" else "prismatic", parent=parent, child=moving,
            origin=np.eye(4), axis=np.array([0.0, 0.0, 1.0]),
            limit=y.Limit(effort=0.0, velocity=float(lim.get("velocity_per_task_time", 10.0)),
                          lower=float(lower), upper=float(upper))))
        if row["type"] == "R":
            origin = _origin((row["a"], 0.0, row["d"]), (row["alpha"], 0.0, 0.0))
        else:
            t = row["theta"]
            origin = _origin((row["a"] * np.cos(t), row["a"] * np.sin(t), 0.0), (row["alpha"], 0.0, t))
        length = float(np.linalg.norm(origin[:3, 3]))
        visuals = [y.Visual(geometry=y.Geometry(sphere=y.Sphere(0.02)), material=grey)]
        links += [y.Link(name=moving, visuals=visuals), y.Link(name=frame)]
        joints.append(y.Joint(name=f"link{i}_dh", type="fixed", parent=moving, child=frame, origin=origin))
        if length > 1e-9:  # draw the link as a cylinder from the joint to the next frame
            direction = origin[:3, 3] / length
            z = np.array([0.0, 0.0, 1.0])
            axis = np.cross(z, direction)
            angle = np.arctan2(np.linalg.norm(axis), z @ direction)
            R = _axis_angle(axis, angle)
            T = np.eye(4)
            T[:3, :3], T[:3, 3] = R, origin[:3, 3] / 2
            visuals.append(y.Visual(origin=T, geometry=y.Geometry(cylinder=y.Cylinder(0.012, length)), material=grey))
        parent = frame
    materials = [grey]
    _cell(data, BASE, parent, links, joints, materials, sphere_radius)
    return y.URDF(robot=y.Robot(name=name, links=links, joints=joints, materials=materials),
                  build_scene_graph=True, load_meshes=False)


def _source_model(data: dict, source: Path):
    """The source URDF with the solution's origin values and absolute relative mesh paths."""
    from designopt.kinematics.urdf import ORIGIN, load_urdf, rpy_of

    model = load_urdf(source)
    robot = model.robot
    by_name = {j.name: j for j in robot.joints}
    for key, value in (data.get("design_joints") or {}).items():
        joint, _, component = key.partition(".origin.")
        if joint not in by_name or component not in {c for c, _, _ in ORIGIN}:
            continue  # a placement joint: the workpiece's, below
        j = by_name[joint]
        T = np.asarray(j.origin if j.origin is not None else np.eye(4), dtype=float)
        roll, pitch, yaw = rpy_of(T[:3, :3])
        parts = dict(zip("xyz", T[:3, 3], strict=True)) | {"roll": roll, "pitch": pitch, "yaw": yaw}
        parts[component] = float(value)
        j.origin = _origin((parts["x"], parts["y"], parts["z"]), (parts["roll"], parts["pitch"], parts["yaw"]))
    for link in robot.links:
        for shape in (*link.visuals, *link.collisions):
            mesh = shape.geometry.mesh if shape.geometry is not None else None
            if mesh is not None and "://" not in mesh.filename and not Path(mesh.filename).is_absolute():
                mesh.filename = str((source.parent / mesh.filename).resolve())
    return model


def _cell(data: dict, base: str, flange: str, links: list, joints: list, materials: list, sphere_radius: float,
          prefix: str = ""):
    """Append the tool frame (under ``flange``), the workpiece with its toolpath and block, and the floor (under
    ``base``) to a robot's links and joints, each name after ``prefix`` (``designopt_`` beside a URDF robot's own
    names: ``designopt_tool``, ``designopt_workpiece``)."""
    import yourdfpy as y

    tool, workpiece, floor_link = prefix + TOOL, prefix + WORKPIECE, prefix + "floor"
    red = y.Material(name=prefix + "path", color=y.Color(rgba=np.array([0.8, 0.1, 0.1, 1.0])))
    materials.append(red)
    links.append(y.Link(name=tool))
    joints.append(y.Joint(name=prefix + "tool_mount", type="fixed", parent=flange, child=tool,
                          origin=np.array(data["tool"])))
    xyz, ypr = data["placement"]["xyz"], data["placement"]["ypr"]
    path_visuals = []
    for k, p in enumerate(data["toolpath"]["points_W"]):
        T = np.eye(4)
        T[:3, 3] = p
        path_visuals.append(y.Visual(name=f"waypoint{k}", origin=T, geometry=y.Geometry(sphere=y.Sphere(sphere_radius)),
                                     material=red))
    collisions = []
    if "cell" in data:  # the workpiece block (its top face is W's z = 0) and the floor, as visuals and collisions
        cell = data["cell"]
        (sx, sy, sz), (cx, cy) = cell["block"]["size"], cell["block"]["center"]
        stock = y.Material(name=prefix + "stock", color=y.Color(rgba=np.array([0.6, 0.6, 0.62, 0.6])))
        materials.append(stock)
        T = np.eye(4)
        T[:3, 3] = (cx, cy, -sz / 2)
        block = y.Geometry(box=y.Box(np.array([sx, sy, sz], dtype=float)))
        path_visuals.append(y.Visual(name="block", origin=T, geometry=block, material=stock))
        collisions.append(y.Collision(name="block", origin=T, geometry=block))
        F = np.eye(4)
        F[:3, 3] = (0.0, 0.0, float(cell["floor"]) - 0.005)
        floor = y.Geometry(box=y.Box(np.array([3.0, 3.0, 0.01])))
        links.append(y.Link(name=floor_link, visuals=[y.Visual(name=floor_link, geometry=floor, material=stock)],
                            collisions=[y.Collision(name=floor_link, geometry=floor)]))
        joints.append(y.Joint(name=prefix + "floor_mount", type="fixed", parent=base, child=floor_link, origin=F))
    links.append(y.Link(name=workpiece, visuals=path_visuals, collisions=collisions))
    joints.append(y.Joint(name=prefix + "placement", type="fixed", parent=base, child=workpiece,
                          origin=_origin(xyz, (ypr[2], ypr[1], ypr[0]))))


def _ets_robot(data: dict, limits: list, links: list, joints: list, material) -> str:
    """URDF joints of an elementary-transform chain: the fixed ETs between two moving ones become the next
    joint's origin. Returns the name of the last link."""
    import yourdfpy as y

    from designopt.verify import rotation, translation

    parent, fixed, i = BASE, np.eye(4), 0
    for et in data["ets"]:
        if et["value"] is not None:
            step = rotation if et["motion"] == "rotate" else translation
            fixed = fixed @ step(et["axis"], et["value"])
            continue
        i += 1
        lim, child = limits[i - 1], f"link{i}"
        revolute = et["motion"] == "rotate"
        joints.append(y.Joint(
            name=lim.get("name", f"joint{i}"), type="revolute" if revolute else "prismatic", parent=parent, child=child,
            origin=fixed, axis=np.array(et["axis"], dtype=float),
            limit=y.Limit(effort=0.0, velocity=float(lim.get("velocity_per_task_time", 10.0)),
                          lower=float(lim.get("lower", -2 * np.pi if revolute else -2.0)),
                          upper=float(lim.get("upper", 2 * np.pi if revolute else 2.0)))))
        links.append(y.Link(name=child, visuals=[y.Visual(geometry=y.Geometry(sphere=y.Sphere(0.02)),
                                                          material=material)]))
        parent, fixed = child, np.eye(4)
    links.append(y.Link(name="flange"))
    joints.append(y.Joint(name="flange_mount", type="fixed", parent=parent, child="flange", origin=fixed))
    return "flange"


def _axis_angle(axis, angle) -> np.ndarray:
    n = np.linalg.norm(axis)
    if n < 1e-12:
        return np.eye(3) if angle < np.pi / 2 else np.diag([1.0, -1.0, -1.0])
    k = axis / n
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def export(data: dict, out_dir: Path, stem: str = "cell") -> list[Path]:
    """Write <stem>.urdf, <stem>_trajectory.csv and <stem>_trajectory.yaml into out_dir: the trajectory headed by
    the URDF's joint names, its time in seconds when the toolpath is timed by a program's feeds (``time_s``), else
    normalised task time (``t_task``)."""
    out_dir.mkdir(parents=True, exist_ok=True)
    urdf_path = out_dir / f"{stem}.urdf"
    urdf_model(data).write_xml_file(str(urdf_path))
    t, Q = data["toolpath"]["t"], data["q"]
    names = joint_names(data)
    seconds = data["toolpath"].get("time_unit") == "s"
    csv_path = out_dir / f"{stem}_trajectory.csv"
    with csv_path.open("w", newline="") as fh:
        writer = csv.writer(fh)
        writer.writerow(["time_s" if seconds else "t_task", *names])
        for tk, q in zip(t, Q, strict=True):
            writer.writerow([tk, *q])
    yaml_path = out_dir / f"{stem}_trajectory.yaml"
    yaml_path.write_text(yaml.safe_dump({
        "joint_names": names, "time_unit": "s" if seconds else "normalised task time in [0, 1]",
        "units": ["rad" if kind == "R" else "m" for kind in data["structure"]],
        "points": [{"t": float(tk), "positions": [float(v) for v in q]} for tk, q in zip(t, Q, strict=True)],
    }, sort_keys=False))
    return [urdf_path, csv_path, yaml_path]
