"""Contact states: one coding end to end, bound from the kernel's enum (_cpp.PairState).

The kernel's pairs, the step results (``states`` arrays), the recorded problems
(tests/data) and the output field ``contact_status`` all use these numbers:

* NONE (0): not a contact node (output fields only);
* OPEN (1): no contact, λ = 0;
* STICK (2): closed, no slip in the increment;
* SLIP (3): closed, sliding on the Coulomb cone;
* CRUSH (4): closed at the normal force's cap of a crushable interface: the surface
  crushes (docs/crushing.md).
"""
from __future__ import annotations

from ._cpp import PairState

NONE = int(PairState.none)
OPEN = int(PairState.open)
STICK = int(PairState.stick)
SLIP = int(PairState.slip)
CRUSH = int(PairState.crush)

STATE_NAMES = {NONE: "none", OPEN: "open", STICK: "stick", SLIP: "slip", CRUSH: "crush"}
"""The name of each state code."""
