"""The default avatar's colours by vertex: skin, a shirt with a crew neck and short sleeves, trousers,
shoes and a hair cap, each bounded by a smooth line drawn on the body at rest (metres, y up, facing
+z, the realizer's rest pose: arms down, palms in).

Why by vertex and not by face: a face has one material, so a region made of whole faces has the
mesh's edges for its border; the neckline and the hairline came out as staircases. A vertex's
colour blends across the faces around it, so a line that cuts across faces stays a line. Each
border is a ramp in the signed distance to its line about one face wide (a narrower one would
make every vertex wholly one side or the other, and the staircase would be back, only blurred).
"""

import numpy as np

COLOURS = {  # linear RGB
    "skin": (0.80, 0.57, 0.45), "shirt": (0.16, 0.30, 0.52), "trousers": (0.18, 0.18, 0.22),
    "shoes": (0.10, 0.07, 0.05), "hair": (0.13, 0.08, 0.05),
}
RAMP = 0.010  # m: the clothes' borders blend over this (the faces there are about 1 cm)
HAIR_RAMP = 0.008  # m: the head's faces are smaller
# The crew neck: the shirt covers what is farther than NECK_RADIUS from the neck's axis (the
# shoulders and chest, up to NECK_TOP) and what is below a line round the neck at the vc7 joint's height behind,
# NECK_DROP lower in front (where the shirt ends just above the breastbone).
NECK_RADIUS = 0.075
NECK_TOP = 0.01  # the shoulders are shirt up to this far above the vc7 joint (m)
NECK_DROP = 0.05
SLEEVE = 0.45  # the sleeves end this share of the way from shoulder to elbow
WAIST = 0.95  # m above the floor: the trousers' top (a little above the vl5 joint)
ANKLE = 0.085  # m above the floor: the shoes' top (a little above the ankle joint)
# The hairline, over the forehead this far above the eyes (m), falling to the nape behind the ears.
HAIRLINE_FRONT = 0.06
HAIRLINE_BACK = -0.085
# The side joints (l_ and r_) that are not an arm's or a hand's.
NOT_ARM = ("hip", "knee", "talocrural", "metatarsal", "eyeball", "sternoclavicular")


def ramp(d, width):
    """0 where d < -width/2, 1 where d > width/2, linear between."""
    return np.clip(0.5 + d / width, 0.0, 1.0)


def is_arm(joint):
    """Whether a joint moves an arm or a hand (shoulder, elbow, wrist, fingers)."""
    return joint[:2] in ("l_", "r_") and not any(k in joint for k in NOT_ARM)


def body_colours(p, main, joints):
    """Each body vertex's colour: p its rest place (n x 3), main the joint that holds it most,
    joints every joint's rest place by name."""
    y, z = p[:, 1], p[:, 2]
    arm = np.array([is_arm(m) for m in main])
    # the crew neck (`front` is 0 behind the neck's axis, 1/2 beside it, 1 before it)
    neck = joints["vc7"]
    dx, dz = p[:, 0] - neck[0], z - neck[2]
    r = np.hypot(dx, dz)
    front = 0.5 * (1.0 + dz / np.maximum(r, 1e-9))
    below = neck[1] - NECK_DROP * front ** 1.5 - y
    beside = np.minimum(r - NECK_RADIUS, neck[1] + NECK_TOP - y)
    shirt = ramp(np.maximum(below, beside), RAMP)
    # the sleeves: a share of the way down each upper arm
    for side in "lr":
        a, b = joints[f"{side}_shoulder"], joints[f"{side}_elbow"]
        length = np.linalg.norm(b - a)
        along = (p - a) @ (b - a) / length
        mine = arm & np.array([m.startswith(side + "_") for m in main])
        shirt[mine] *= ramp(SLEEVE * length - along[mine], RAMP)
    trousers = np.where(arm, 0.0, ramp(WAIST - y, RAMP))
    shoes = np.where(arm, 0.0, ramp(ANKLE - y, RAMP))
    # the hair cap: above a line over the forehead that falls behind the ears to the nape
    eyes = 0.5 * (joints["l_eyeball_joint"] + joints["r_eyeball_joint"])
    behind = np.clip(-(z - eyes[2] + 0.04) / 0.1, 0.0, 1.0)
    line = HAIRLINE_FRONT + (HAIRLINE_BACK - HAIRLINE_FRONT) * behind
    hair = np.where(arm, 0.0, ramp(y - eyes[1] - line, HAIR_RAMP))
    # shoes over trousers over the shirt; the hair never meets them
    w = {"shoes": shoes}
    w["trousers"] = trousers * (1.0 - shoes)
    w["shirt"] = shirt * (1.0 - trousers) * (1.0 - shoes)
    w["hair"] = hair * (1.0 - shirt)
    w["skin"] = 1.0 - sum(w.values())
    return sum(np.outer(w[k], COLOURS[k]) for k in w)
