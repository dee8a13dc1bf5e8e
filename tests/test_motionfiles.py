"""Motion exchange with the field's tools: a reference written as GMR's robot-motion
pickle and as LocoMuJoCo's trajectory ``.npz``, read back, read in those projects' own
layouts, learned from, and hostile files refused."""

from __future__ import annotations

import pickle

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from imitwalk.errors import MocapError


@pytest.fixture(scope="module")
def walk(robot, tiny_reference):
    """The tiny reference's walk from standing as a robot motion."""
    from imitwalk.retarget.robotmotion import motion_of_reference

    ref, _ = tiny_reference
    return motion_of_reference(ref, robot, cycles=3)


def _close(a, b, tol=1e-6):
    return (
        np.abs(a.joints - b.joints).max() <= tol
        and np.abs(a.root_pos - b.root_pos).max() <= tol
        and np.abs(np.abs(np.sum(a.root_quat * b.root_quat, axis=1)) - 1).max() <= tol
        and a.fps == b.fps
        and a.joint_names == b.joint_names
    )


@pytest.mark.parametrize("suffix", [".pkl", ".npz"])
def test_a_reference_round_trips_through_gmr_and_locomujoco(walk, robot, tmp_path, suffix):
    from imitwalk.retarget.motionfiles import read_robot_motion, write_gmr, write_locomujoco

    path = tmp_path / f"walk{suffix}"
    (write_gmr if suffix == ".pkl" else write_locomujoco)(walk, robot, path)
    assert _close(read_robot_motion(path, robot), walk)


def test_the_walk_from_a_reference_travels_on_its_feet(walk, tiny_reference):
    """Kinematic anchoring: the base moves forward by the reference's strides, at a
    steady height, and turns little."""
    ref, _ = tiny_reference
    planned = ref.expected_distance(float(ref.scales[-1]), walk.n_frames * ref.dt)
    travel = walk.root_pos[-1, 0] - walk.root_pos[0, 0]
    assert travel == pytest.approx(planned, rel=0.1)
    assert np.ptp(walk.root_pos[:, 2]) < 0.03


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), frames=st.integers(2, 40))
def test_any_motion_round_trips_exactly(robot, tmp_path_factory, seed, frames):
    from imitwalk.retarget.motionfiles import read_robot_motion, write_gmr, write_locomujoco
    from imitwalk.retarget.robotmotion import RobotMotion

    rng = np.random.default_rng(seed)
    lo, hi = robot.limits[:, 0], robot.limits[:, 1]
    quat = rng.normal(size=(frames, 4))
    m = RobotMotion(
        robot.name,
        float(rng.choice([30, 50, 100, 120])),
        rng.normal(size=(frames, 3)),
        quat / np.linalg.norm(quat, axis=1, keepdims=True),
        lo + (hi - lo) * rng.random((frames, robot.dof)),
        robot.joint_names,
    )
    out = tmp_path_factory.mktemp("rt")
    write_gmr(m, robot, out / "m.pkl")
    write_locomujoco(m, robot, out / "m.npz")
    assert _close(read_robot_motion(out / "m.pkl", robot), m, 1e-9)
    assert _close(read_robot_motion(out / "m.npz", robot), m, 1e-9)


def _qpos(walk, robot):
    from imitwalk.retarget.robotmotion import MotionModel

    return MotionModel(robot).qpos(walk.root_pos, walk.root_quat, walk.joints)


def test_a_gmr_file_as_gmr_writes_it_is_read(walk, robot, tmp_path):
    """GMR's scripts pickle a dict: fps (int), root_pos, root_rot (x, y, z, w), dof_pos
    (the model's qpos[7:]), local_body_pos and link_body_list (None)."""
    from imitwalk.retarget.motionfiles import read_robot_motion

    q = _qpos(walk, robot)
    data = {
        "fps": 100,
        "root_pos": q[:, :3],
        "root_rot": q[:, 3:7][:, [1, 2, 3, 0]],
        "dof_pos": q[:, 7:].astype(np.float32),
        "local_body_pos": None,
        "link_body_list": None,
    }
    path = tmp_path / "gmr.pkl"
    with path.open("wb") as f:
        pickle.dump(data, f)
    assert _close(read_robot_motion(path, robot), walk, 1e-6)


def test_a_trajectory_as_locomujoco_saves_it_is_read(walk, robot, tmp_path):
    """LocoMuJoCo's ``Trajectory.save``: ``np.savez`` of its data, info and model fields,
    the unset ones as pickled ``None`` (never unpickled here)."""
    import mujoco

    from imitwalk.retarget.motionfiles import read_robot_motion

    m = robot.compile()
    q = _qpos(walk, robot)
    names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_JOINT, j) or "root" for j in range(m.njnt)]
    path = tmp_path / "traj.npz"
    np.savez(
        path,
        qpos=np.vstack([q, q[:5]]),  # a second trajectory after the first
        qvel=np.zeros((len(q) + 5, m.nv)),
        xpos=np.empty(0),
        xquat=np.empty(0),
        cvel=np.empty(0),
        subtree_com=np.empty(0),
        site_xpos=np.empty(0),
        site_xmat=np.empty(0),
        split_points=np.array([0, len(q), len(q) + 5]),
        joint_names=np.array(names),
        frequency=np.array(100.0),
        body_names=np.array(None, dtype=object),
        site_names=np.array(None, dtype=object),
        metadata=np.array(None, dtype=object),
        njnt=np.array(m.njnt),
        jnt_type=np.asarray(m.jnt_type),
        nbody=np.array(None, dtype=object),
        body_rootid=np.empty(0),
    )
    assert _close(read_robot_motion(path, robot), walk, 1e-9)


def test_a_robot_motion_gives_the_stepping_gait_the_clips_style(walk, robot, tiny_reference):
    """Read back as a clip (forward kinematics), the reference's walk has the timing and
    the stride of the clip it was retargeted from."""
    from imitwalk.retarget.robotmotion import clip_of_motion
    from imitwalk.step.pipeline import gait_from_motion

    ref, _ = tiny_reference
    style = gait_from_motion(clip_of_motion(walk, robot), robot).style
    assert style.step_time == pytest.approx(ref.period / 2, rel=0.05)
    _, _, stride = ref.at_scale(float(ref.scales[-1]))
    assert 2 * style.step_length == pytest.approx(stride, rel=0.15)


def test_learn_reads_a_gmr_file_as_its_clip(walk, robot, tmp_path, capsys):
    from imitwalk.cli import main
    from imitwalk.retarget.motionfiles import write_gmr
    from tests.conftest import TINY_STEP, sets

    path = write_gmr(walk, robot, tmp_path / "walk.pkl")
    assert main(["learn", str(path), "--out", str(tmp_path / "run"), *sets(TINY_STEP)]) == 0
    assert "walk.pkl" in capsys.readouterr().err


class _Evil:
    def __reduce__(self):
        import os

        return (os.system, ("touch PWNED",))


@pytest.mark.parametrize(
    ("what", "word"),
    [
        ("code", "posix.system"),
        ("truncated", "not a GMR"),
        ("other robot", "another robot"),
        ("not finite", "not finite"),
        ("not a dict", "needs fps"),
    ],
)
def test_a_hostile_gmr_file_is_refused_in_one_line(walk, robot, tmp_path, monkeypatch, what, word):
    from imitwalk.retarget.motionfiles import read_robot_motion, write_gmr

    monkeypatch.chdir(tmp_path)
    path = write_gmr(walk, robot, tmp_path / "walk.pkl")
    data = pickle.loads(path.read_bytes())
    if what == "code":
        raw = pickle.dumps({**data, "fps": _Evil()})
    elif what == "truncated":
        raw = path.read_bytes()[:200]
    elif what == "other robot":
        raw = pickle.dumps({**data, "dof_pos": data["dof_pos"][:, :-2]})
    elif what == "not finite":
        data["root_pos"][3, 1] = np.nan
        raw = pickle.dumps(data)
    else:
        raw = pickle.dumps([1, 2, 3])
    path.write_bytes(raw)
    with pytest.raises(MocapError) as err:
        read_robot_motion(path, robot)
    assert word in str(err.value) and "\n" not in str(err.value)
    assert not (tmp_path / "PWNED").exists()


def test_a_locomujoco_file_of_another_robot_is_refused(walk, robot, tmp_path):
    from imitwalk.retarget.motionfiles import read_robot_motion, write_locomujoco

    path = write_locomujoco(walk, robot, tmp_path / "t.npz")
    z = dict(np.load(path))
    z["joint_names"] = np.array([n.replace("knee", "kn") for n in z["joint_names"]])
    np.savez(path, **z)
    with pytest.raises(MocapError, match="another robot"):
        read_robot_motion(path, robot)


def test_convert_writes_both_formats_and_refuses_bad_input(tiny_reference, tmp_path, capsys):
    from imitwalk.cli import main

    _, ref_path = tiny_reference
    assert main(["convert", str(ref_path), "--to", "gmr", "--out", str(tmp_path / "a.pkl")]) == 0
    assert (
        main(
            [
                "convert",
                str(tmp_path / "a.pkl"),
                "--to",
                "locomujoco",
                "--out",
                str(tmp_path / "b.npz"),
            ]
        )
        == 0
    )
    capsys.readouterr()
    bad = [
        (
            ["convert", str(ref_path), "--to", "bvh", "--out", str(tmp_path / "c.bvh")],
            "valid: gmr, locomujoco",
        ),
        (["convert", str(ref_path), "--to", "gmr", "--out", str(tmp_path / "c.npz")], ".pkl"),
        (
            [
                "convert",
                str(tmp_path / "none.pkl"),
                "--to",
                "gmr",
                "--out",
                str(tmp_path / "d.pkl"),
            ],
            "not found",
        ),
        (
            [
                "convert",
                str(ref_path),
                "--to",
                "gmr",
                "--out",
                str(tmp_path / "e.pkl"),
                "--cycles",
                "0",
            ],
            "--cycles",
        ),
        (  # a bound: 100 000 cycles ran for minutes, its memory growing
            [
                "convert",
                str(ref_path),
                "--to",
                "gmr",
                "--out",
                str(tmp_path / "f.pkl"),
                "--cycles",
                "100000",
            ],
            "expected 1 to 1000",
        ),
        (  # a robot motion is written as it is: a reference's settings are not ignored
            [
                "convert",
                str(tmp_path / "a.pkl"),
                "--to",
                "locomujoco",
                "--out",
                str(tmp_path / "g.npz"),
                "--scale",
                "0.5",
            ],
            "--scale: only for a reference",
        ),
        (
            ["convert", str(tmp_path), "--to", "gmr", "--out", str(tmp_path / "h.pkl")],
            "is a folder",
        ),
    ]
    for argv, word in bad:
        assert main(argv) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert err[-1].startswith("error: ") and word in err[-1], (argv, err)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.pkl", "b.npz"]


@pytest.mark.parametrize("kind", ["reference", "locomujoco"])
@pytest.mark.parametrize("keep", [0, 300, -200])
def test_convert_refuses_a_damaged_npz_in_one_line_as_playback_does(
    walk, robot, tiny_reference, tmp_path, capsys, kind, keep
):
    """A truncated (first 300 bytes, or all but the last 200) or empty ``.npz``: exit 2 and
    one line from the checked reader ``playback`` uses (the same line for a truncated
    file), no zip traceback."""
    from imitwalk.cli import main
    from imitwalk.retarget.motionfiles import write_locomujoco

    _, ref_path = tiny_reference
    good = ref_path if kind == "reference" else write_locomujoco(walk, robot, tmp_path / "t.npz")
    raw = good.read_bytes()
    bad = tmp_path / "truncated.npz"
    bad.write_bytes(raw[:keep])
    out = tmp_path / "x.pkl"
    assert main(["convert", str(bad), "--to", "gmr", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert "Traceback" not in "\n".join(err) and err[-1].startswith("error: "), err
    assert ("empty" if keep == 0 else "truncated or corrupt") in err[-1], err
    assert not out.exists()
    assert main(["playback", str(bad)]) == 2
    same = capsys.readouterr().err.strip().splitlines()[-1] == err[-1]
    assert same or keep == 0  # an empty file: each names what it expected
