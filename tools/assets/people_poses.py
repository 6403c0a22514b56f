"""The people's poses (make_people.py): joint positions for standing, a walking mid-stride, the
walking cycle's phases (gait_angles) and riding a bicycle, from a figure's rest-pose skeleton
(joint name -> (x, y, z)). Frame: x forward, y left, z up."""
import math

from meshkit import add, cross, dot, mat_vec, mul, norm, rot_y, sub


def rotation_between(a, b):
    """The smallest rotation taking direction a onto direction b (Rodrigues)."""
    a, b = norm(a), norm(b)
    v = cross(a, b)
    c = dot(a, b)
    s2 = dot(v, v)
    if s2 < 1e-12:
        return ((1, 0, 0), (0, 1, 0), (0, 0, 1))
    k = (1 - c) / s2
    vx = ((0, -v[2], v[1]), (v[2], 0, -v[0]), (-v[1], v[0], 0))
    vx2 = tuple(tuple(sum(vx[i][n] * vx[n][jj] for n in range(3)) for jj in range(3)) for i in range(3))
    return tuple(tuple((1 if i == jj else 0) + vx[i][jj] + k * vx2[i][jj] for jj in range(3)) for i in range(3))


def swing(v, angle):
    """v turned forward (towards +x, about +y... i.e. a hanging limb swings to +x) by angle."""
    return mat_vec(rot_y(-angle), v)


def pose_walk(rest, f):
    """A mid-stride walking pose: left heel strikes, right toes push off, arms opposite."""
    j = dict(rest)
    lean = math.radians(4)
    # torso and everything above it lean forward about the waist
    w = rest["waist"]
    for k in ("neck_base", "head_base", "head_top", "shoulder_l", "shoulder_r"):
        j[k] = add(w, swing(sub(rest[k], w), -lean))  # (swing turns upward vectors back)
    j["head_top"] = add(j["head_base"], sub(rest["head_top"], rest["head_base"]))  # head level
    legs = {"l": (math.radians(14), math.radians(4), math.radians(7)),
            "r": (math.radians(-10), None, math.radians(-20))}

    def leg(k, thigh, knee, foot_angle):
        hip = rest["hip_" + k]
        kn = add(hip, swing(sub(rest["knee_" + k], hip), thigh))
        an = add(kn, swing(sub(rest["ankle_" + k], rest["knee_" + k]), thigh - knee))
        to = add(an, swing(sub(rest["toe_" + k], rest["ankle_" + k]), foot_angle))
        return kn, an, to

    # left: heel strike; right: knee bent so that its toe is as low as the left heel
    kl, al, tl = leg("l", *legs["l"])
    heel_l = al[2] - 0.045 * f["h"] * 1.0
    lo, hi = 0.0, math.radians(60)
    for _ in range(40):
        mid = 0.5 * (lo + hi)
        kr, ar, tr = leg("r", legs["r"][0], mid, legs["r"][2])
        if tr[2] < heel_l + 0.012:
            lo = mid
        else:
            hi = mid
    kr, ar, tr = leg("r", legs["r"][0], 0.5 * (lo + hi), legs["r"][2])
    j.update({"knee_l": kl, "ankle_l": al, "toe_l": tl, "knee_r": kr, "ankle_r": ar, "toe_r": tr})
    # arms swing against the legs, elbows bent
    for k, sw, el in (("l", -15, 15), ("r", 13, 22)):
        sh = j["shoulder_" + k]
        sw, el = math.radians(sw), math.radians(el)
        e = add(sh, swing(sub(rest["elbow_" + k], rest["shoulder_" + k]), sw))
        wr = add(e, swing(sub(rest["wrist_" + k], rest["elbow_" + k]), sw + el))
        ft = add(wr, swing(sub(rest["fingertip_" + k], rest["wrist_" + k]), sw + el))
        j.update({"elbow_" + k: e, "wrist_" + k: wr, "fingertip_" + k: ft})
    return j


WALK_FRAMES = 8  # poses of the walking cycle (walk_phase k / WALK_FRAMES)


def bump(phase, centre, width):
    """A smooth bump of height 1 at `centre` on the cycle (phase and centre in [0, 1))."""
    d = (phase - centre + 0.5) % 1.0 - 0.5
    return math.exp(-(d / width) ** 2)


def gait_angles(phase):
    """Joint angles (degrees) of the walking cycle at `phase` (RoadUser.walk_phase: 0 and 0.5
    feet together, the left heel striking at 0.25, the right at 0.75): per side, the thigh's
    swing forward, the knee's bend, the foot's angle (toes up positive), the arm's swing
    forward and the elbow's bend. Hips +-A sin, the swinging leg's knee bent most as it
    passes the other, the foot up at heel strike and down at push-off, the arms opposite."""
    out = {}
    for k, shift in (("l", 0.0), ("r", 0.5)):
        q = (phase + shift) % 1.0  # this leg's phase: heel strike at 0.25, push-off ~0.7
        thigh = 3.0 + 18.0 * math.sin(2 * math.pi * q)
        knee = 5.0 + 10.0 * bump(q, 0.35, 0.08) + 45.0 * bump(q, 0.97, 0.1)
        foot = 8.0 * bump(q, 0.25, 0.06) - 22.0 * bump(q, 0.72, 0.07) + 4.0 * bump(q, 0.0, 0.1)
        arm = -18.0 * math.sin(2 * math.pi * q)
        elbow = 14.0 + 0.6 * max(0.0, arm)
        out[k] = (thigh, knee, foot, arm, elbow)
    return out


def pose_cycle(rest, f, phase):
    """The walking cycle's pose at `phase` (see gait_angles); the trunk leans forward 4
    degrees. The figure is not lifted here: its lowest point goes onto the ground after."""
    j = dict(rest)
    lean = math.radians(4)
    w = rest["waist"]
    for k in ("neck_base", "head_base", "head_top", "shoulder_l", "shoulder_r"):
        j[k] = add(w, swing(sub(rest[k], w), -lean))
    j["head_top"] = add(j["head_base"], sub(rest["head_top"], rest["head_base"]))
    for k, (thigh, knee, foot_angle, arm, elbow) in gait_angles(phase).items():
        thigh, knee, foot_angle = math.radians(thigh), math.radians(knee), math.radians(foot_angle)
        hip = rest["hip_" + k]
        kn = add(hip, swing(sub(rest["knee_" + k], hip), thigh))
        an = add(kn, swing(sub(rest["ankle_" + k], rest["knee_" + k]), thigh - knee))
        to = add(an, swing(sub(rest["toe_" + k], rest["ankle_" + k]), foot_angle))
        sh = j["shoulder_" + k]
        sw, el = math.radians(arm), math.radians(elbow)
        e = add(sh, swing(sub(rest["elbow_" + k], rest["shoulder_" + k]), sw))
        wr = add(e, swing(sub(rest["wrist_" + k], rest["elbow_" + k]), sw + el))
        ft = add(wr, swing(sub(rest["fingertip_" + k], rest["wrist_" + k]), sw + el))
        j.update({"knee_" + k: kn, "ankle_" + k: an, "toe_" + k: to,
                  "elbow_" + k: e, "wrist_" + k: wr, "fingertip_" + k: ft})
    return j


def pose_stand(rest, f):
    j = dict(rest)
    for k, sw in (("l", 3), ("r", -2)):
        sw = math.radians(sw)
        sh = rest["shoulder_" + k]
        e = add(sh, swing(sub(rest["elbow_" + k], sh), sw))
        wr = add(e, swing(sub(rest["wrist_" + k], rest["elbow_" + k]), sw + math.radians(10)))
        ft = add(wr, swing(sub(rest["fingertip_" + k], rest["wrist_" + k]), sw + math.radians(10)))
        j.update({"elbow_" + k: e, "wrist_" + k: wr, "fingertip_" + k: ft})
    return j


def two_bone(a, target, la, lb, pole):
    """The middle joint of a two-bone chain from a reaching `target`, bending towards pole."""
    d = sub(target, a)
    dist = math.sqrt(dot(d, d))
    dist = min(dist, la + lb - 1e-4)
    u = norm(d)
    along = (la * la - lb * lb + dist * dist) / (2 * dist)
    h = math.sqrt(max(0.0, la * la - along * along))
    v = norm(sub(pole, mul(u, dot(pole, u))))
    return add(add(a, mul(u, along)), mul(v, h)), add(a, mul(u, dist))


def pose_cyclist(rest, f, bike):
    """Seated on the saddle, leaning forward, hands on the grips, feet on the pedals."""
    j = dict(rest)
    # the pelvis: the hips just above and ahead of the saddle's top
    hip_c = (bike["saddle"][0] + 0.02, 0.0, bike["saddle"][2] + 0.07)
    shift = sub(hip_c, rest["hip_c"])
    lean = math.radians(38)
    pel_tilt = math.radians(20)
    hc = rest["hip_c"]
    for k in list(j):
        j[k] = add(rest[k], shift)
    # the pelvis tips forward; the torso leans about the waist
    for k in ("waist", "hip_l", "hip_r"):
        j[k] = add(hip_c, swing(sub(rest[k], hc), -pel_tilt))
    w0, w = rest["waist"], j["waist"]
    for k in ("neck_base", "head_base", "head_top", "shoulder_l", "shoulder_r"):
        j[k] = add(w, swing(sub(rest[k], w0), -lean))
    j["head_top"] = add(j["head_base"], swing(sub(rest["head_top"], rest["head_base"]), -math.radians(12)))
    # legs and arms by two-bone reaching
    for k in ("l", "r"):
        la = dist(rest["hip_" + k], rest["knee_" + k])
        lb = dist(rest["knee_" + k], rest["ankle_" + k])
        target = add(bike["pedals"][k], (-0.02, 0.0, 0.08))
        target = (target[0], j["hip_" + k][1] * 1.05, target[2])
        knee, ankle = two_bone(j["hip_" + k], target, la, lb, (1.0, 0.0, 0.4))
        j["knee_" + k], j["ankle_" + k] = knee, ankle
        foot_dir = sub(rest["toe_" + k], rest["ankle_" + k])
        j["toe_" + k] = add(ankle, swing(foot_dir, math.radians(-12)))
        ua = dist(rest["shoulder_" + k], rest["elbow_" + k])
        fa = dist(rest["elbow_" + k], rest["wrist_" + k])
        grip = bike["grips"][k]
        wrist_t = add(grip, (-0.03, 0.0, 0.01))
        side = 1 if k == "l" else -1
        elbow, wrist = two_bone(j["shoulder_" + k], wrist_t, ua, fa, (-0.6, side * 0.8, -0.6))
        j["elbow_" + k], j["wrist_" + k] = elbow, wrist
        hand = sub(rest["fingertip_" + k], rest["wrist_" + k])
        j["fingertip_" + k] = add(wrist, mat_vec(rotation_between(sub(rest["wrist_" + k], rest["elbow_" + k]), sub(wrist, elbow)), hand))
    return j


def dist(a, b):
    d = sub(a, b)
    return math.sqrt(dot(d, d))
