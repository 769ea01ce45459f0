"""The pads and their groups the synthetic signals of the metrics' tests carry (as the
robot's contact pads are named in signals.npz)."""

PADS = {
    "l_sole_pad": "soles",
    "r_sole_pad": "soles",
    "l_thigh_pad": "thighs",
    "r_thigh_pad": "thighs",
    "buttocks_pad": "buttocks",
}
