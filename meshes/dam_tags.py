"""Tag numbers of the gravity-dam geometry (meshes/dam.py), apart from meshes/tags.py.

Cells: the dam, its foundation and the log are three bodies of one mesh. The dam and the
foundation share their nodes along the base (bonded, conforming); the log shares none.

Facets (both 2D and 3D unless noted):

==========================  =======================================================
name                        meaning
==========================  =======================================================
``foundation_bottom``       bottom of the foundation (clamped in stage 1)
``foundation_sides``        upstream and downstream ends of the foundation (rollers)
``foundation_flanks``       3D: the two faces normal to the dam axis (rollers)
``reservoir_bed``           foundation top upstream of the heel (under the reservoir)
``tailwater_bed``           foundation top downstream of the toe
``dam_base``                dam/foundation interface (interior facets: the base section)
``dam_upstream``            vertical upstream face, split at the water line; the dam's
                            contact candidate surface for the log
``dam_crest``               crest
``dam_downstream``          downstream face (vertical part under the crest and slope)
``dam_flanks``              3D: the dam block's two faces normal to the dam axis
``log_upper``               2D: the log's upper long edge (contact candidate)
``log_lower``               2D: the log's lower long edge (contact candidate)
``log_mantle``              3D: the log's cylindrical surface (contact candidate)
``log_front``               the log's end facing the dam (contact candidate)
``log_back``                the log's other end
==========================  =======================================================
"""

DAM = 101
FOUNDATION = 102
LOG = 103

FOUNDATION_BOTTOM = 111
FOUNDATION_SIDES = 112
FOUNDATION_FLANKS = 113
RESERVOIR_BED = 114
TAILWATER_BED = 115
DAM_BASE = 120
DAM_UPSTREAM = 121
DAM_CREST = 122
DAM_DOWNSTREAM = 123
DAM_FLANKS = 124
LOG_UPPER = 130
LOG_LOWER = 131
LOG_MANTLE = 132
LOG_FRONT = 133
LOG_BACK = 134

NAMES = {DAM: "dam", FOUNDATION: "foundation", LOG: "log",
         FOUNDATION_BOTTOM: "foundation_bottom", FOUNDATION_SIDES: "foundation_sides",
         FOUNDATION_FLANKS: "foundation_flanks", RESERVOIR_BED: "reservoir_bed",
         TAILWATER_BED: "tailwater_bed", DAM_BASE: "dam_base", DAM_UPSTREAM: "dam_upstream",
         DAM_CREST: "dam_crest", DAM_DOWNSTREAM: "dam_downstream", DAM_FLANKS: "dam_flanks",
         LOG_UPPER: "log_upper", LOG_LOWER: "log_lower", LOG_MANTLE: "log_mantle",
         LOG_FRONT: "log_front", LOG_BACK: "log_back"}

CELL_TAGS = (DAM, FOUNDATION, LOG)
FACET_TAGS_2D = (FOUNDATION_BOTTOM, FOUNDATION_SIDES, RESERVOIR_BED, TAILWATER_BED, DAM_BASE,
                 DAM_UPSTREAM, DAM_CREST, DAM_DOWNSTREAM, LOG_UPPER, LOG_LOWER, LOG_FRONT,
                 LOG_BACK)
FACET_TAGS_3D = (FOUNDATION_BOTTOM, FOUNDATION_SIDES, FOUNDATION_FLANKS, RESERVOIR_BED,
                 TAILWATER_BED, DAM_BASE, DAM_UPSTREAM, DAM_CREST, DAM_DOWNSTREAM, DAM_FLANKS,
                 LOG_MANTLE, LOG_FRONT, LOG_BACK)
