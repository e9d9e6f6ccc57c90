"""Tag numbers shared by all builders (see the package docstring)."""

BASE = 1
UPPER = 2
FIXED = 10
LOADED = 11
SYMMETRY_X = 12
SYMMETRY_Y = 13
MASTER = 20
SLAVE = 21

NAMES = {BASE: "base", UPPER: "upper", FIXED: "fixed", LOADED: "loaded",
         SYMMETRY_X: "symmetry_x", SYMMETRY_Y: "symmetry_y", MASTER: "master", SLAVE: "slave"}
