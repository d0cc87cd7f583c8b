"""Declarations of every skill the shipped plans bind (IMPERA Section 6.4).

Plain data only: ``alica validate`` checks behaviours against these
declarations without importing any robotics library. A skill's ``implementation`` names
the py_trees behaviour class that runs it (imported only when it runs), or is
``None`` while the skill has none yet.

Two layers:

* **composite skills** are whole robot abilities (drive to a goal, pick up a
  sample, stack a block). Other planners (e.g. a ProTaP dispatcher) and the
  blocks-world skill plans call them directly.
* **primitive skills** are the steps of the ALICA skill plans under
  ``plans/skills/`` (Figs. 7, 8, 10, 13, 15 and 16 of the paper); each state
  of those plans runs one of them.

The catalogue is a skill plug-in like any other: this package lists
:func:`register` under the entry-point group ``alica.skills``, so
:func:`alica.lang.skill_plugins.default_registry` loads it without the
language layer importing this one.

Capabilities name what a robot needs to run a skill; role sets list the same
words under ``requires`` (``base``, ``arm``, ``gripper``, ``lidar2d``,
``camera``, ``lidar3d``, ``stereo_camera``).
"""

from __future__ import annotations

from alica.lang.skills import ParamSpec, SkillRegistry


def _p(name: str, type: str, doc: str, *, default: object = None, required: bool | None = None) -> ParamSpec:
    """A parameter; required unless a default is given or ``required=False``."""
    if required is None:
        required = default is None
    return ParamSpec(name, type, required, None if required else default, doc)


def _drive_params() -> tuple[ParamSpec, ...]:
    """The parameters of MoveToPosition and DriveTo: one implementation runs both."""
    return (
        _p("goal", "position", "where to drive: [x, y], [x, y, z] or a term such as pos(a)"),
        _p("tolerance", "float", "distance in metres at which the goal counts as reached", default=0.3),
        _p("timeout", "float", "seconds from the start before the skill gives up", default=60.0),
        _p(
            "at",
            "object",
            "the object or place driven to: on arrival the skill writes at(robot, at) (a goal given as pos(x) does too)",
            required=False,
        ),
    )


def _composite(registry: SkillRegistry) -> None:
    registry.declare(
        "MoveToPosition",
        *_drive_params(),
        doc="drive to a goal position, escaping into free space when stuck (Fig. 8)",
        capabilities=("base",),
        implementation="alica.skills.navigation:MoveToPosition",
    )
    registry.declare(
        "Pickup",
        _p("object", "object", "the object to pick up"),
        _p("retries", "int", "grasp attempts before the skill fails", default=3),
        doc="align with an object, grasp it, lift it to the transport pose and check the grip (Fig. 15)",
        capabilities=("base", "arm", "gripper"),
        implementation="alica.skills.handling:Pickup",
    )
    registry.declare(
        "Putdown",
        _p("object", "object", "the held object to put down"),
        _p(
            "target",
            "position",
            "where to place it: a position or a term such as pos(g); by default in front of the robot",
            required=False,
        ),
        _p(
            "spread",
            "float",
            "without a target: put it down at the nearest spot this many metres from every block "
            "and every stand-off point a teammate reserved, where there is one (0: in front of the robot)",
            default=0.0,
        ),
        doc="place the held object, open the gripper, stow the arm and check the placement (Fig. 16)",
        capabilities=("arm", "gripper"),
        implementation="alica.skills.handling:Putdown",
    )
    registry.declare(
        "Stack",
        _p("object", "object", "the held block to place"),
        _p("target", "object", "the block to place it on"),
        doc="put the held block on top of another block",
        capabilities=("base", "arm", "gripper"),
        implementation="alica.skills.handling:Stack",
    )
    registry.declare(
        "Unstack",
        _p("object", "object", "the top block to take"),
        _p("from", "object", "the block it currently lies on"),
        doc="take the top block off a stack and hold it",
        capabilities=("base", "arm", "gripper"),
        implementation="alica.skills.handling:Unstack",
    )
    registry.declare(
        "Explore",
        _p(
            "spacing",
            "float",
            "minimal distance in metres between the frontiers of different robots (eps of Eq. 7)",
            default=4.0,
        ),
        _p("timeout", "float", "seconds before the skill stops; 0 explores until no frontier is left", default=0.0),
        doc="explore unknown terrain frontier by frontier until the map is complete (Fig. 7)",
        capabilities=("base", "lidar2d"),
    )


def _free_space_params(keep_away: str) -> tuple[ParamSpec, ...]:
    """``clearance``, ``max_distance`` and ``keep_away`` (documented as given) of the skills that look for free space."""
    return (
        _p("clearance", "float", "distance in metres to keep from obstacles, robots and work sites", default=1.0),
        _p("max_distance", "float", "farthest the robot may drive to find such a place", default=3.0),
        _p("keep_away", "float", keep_away, default=0.0),
    )


def _navigation(registry: SkillRegistry) -> None:
    registry.declare(
        "DriveTo",
        *_drive_params(),
        doc="follow a collision-free path to a goal; fails when stuck",
        capabilities=("base",),
        implementation="alica.skills.navigation:MoveToPosition",
    )
    registry.declare(
        "DriveToFreeSpace",
        *_free_space_params("distance in metres to keep from every block or sample lying in the world (0: none)"),
        doc="drive to the nearest position with the given clearance, e.g. out of a corner or out of the way",
        capabilities=("base",),
        implementation="alica.skills.navigation:DriveToFreeSpace",
    )
    registry.declare(
        "WaitAside",
        *_free_space_params(
            "distance in metres to keep from every block or sample lying in the world but the work site's (0: none)"
        ),
        _p("near", "object", "the work site of the robot's next step: wait on a ring around it", required=False),
        _p(
            "guard",
            "object",
            "a finished part of the goal: stay within guard_radius of it, so that opponents leave it alone",
            required=False,
        ),
        _p("guard_radius", "float", "metres from the guarded object within which the robot stays", default=0.9),
        _p(
            "threat_radius",
            "float",
            "guard only while a robot outside the team is within this many metres of the guarded object, else "
            "stand by (0: always guard)",
            default=0.0,
        ),
        doc="wait out of the way of the team's work: near the next work site, guarding a finished stack, or away "
        "from every stack; clear of the other robots and of the stand-off points teammates reserved; moves on when "
        "a teammate needs the place; runs until its state is left",
        capabilities=("base",),
        implementation="alica.skills.waiting:WaitAside",
    )
    registry.declare(
        "DriveToDroppedSample",
        _p("distance", "float", "look from this many metres off where the dropped sample was last seen", default=1.5),
        _p("period", "float", "seconds between two looks for a dropped sample while there is none", default=1.0),
        _p("timeout", "float", "seconds of driving before the skill fails", default=120.0),
        doc="stand still until a lost teammate held a sample (its gripper opened when it crashed), then drive near "
        "where the sample was last seen, for the perception to find it again",
        capabilities=("base",),
        implementation="alica.skills.sample_search:DriveToDroppedSample",
    )
    registry.declare(
        "Localize",
        _p("timeout", "float", "seconds before the skill fails", default=30.0),
        _p("continuous", "bool", "keep correcting every period until the state is left", default=False),
        _p("period", "float", "seconds between two scan matches", default=0.5),
        _p(
            "max_range",
            "float",
            "lidar range in metres used for matching (as far as BuildMap maps, by default: hits beyond the map cannot match)",
            default=10.0,
        ),
        doc="localize the robot in the shared map: match lidar scans against it and correct the pose estimate",
        capabilities=("base",),
        implementation="alica.skills.mapping:Localize",
    )
    registry.declare(
        "BuildMap",
        _p("resolution", "float", "cell size of the occupancy grid in metres", default=0.05),
        _p("radius", "float", "radius in metres around the start to map before the map counts as ready", default=5.0),
        _p("max_range", "float", "lidar range in metres traced into the map", default=10.0),
        _p("timeout", "float", "seconds before the skill fails", default=30.0),
        doc="build the team's first occupancy map around the robot and share it; asserts mapped",
        capabilities=("base", "lidar2d"),
        implementation="alica.skills.mapping:BuildMap",
    )
    registry.declare(
        "ExploreFrontier",
        _p(
            "frontier",
            "object",
            "frontier cell to drive to; by default the best free one by information gain",
            required=False,
        ),
        _p(
            "spacing",
            "float",
            "minimal distance in metres to the frontiers of other robots (eps of Eq. 7)",
            default=4.0,
        ),
        _p("reach", "float", "range in metres of the wave fronts of Algorithm 1 (information gain)", default=3.0),
        _p(
            "min_gain",
            "float",
            "frontiers with at most this information gain in square metres count as explored",
            default=1.0,
        ),
        _p("period", "float", "seconds between two readings of the map (frontiers published to the team)", default=1.0),
        _p("tolerance", "float", "distance in metres at which a frontier counts as reached", default=0.5),
        _p(
            "reassign",
            "bool",
            "follow the team's solution at every reading of the map, not only when a frontier is needed "
            "(with the Explore plan's KeepFrontier hysteresis)",
            default=False,
        ),
        doc="drive to frontier cells in order of information gain and boundary relation, updating the map",
        capabilities=("base",),
        implementation="alica.skills.exploration.skill:ExploreFrontier",
    )
    registry.declare(
        "Idle",
        _p("duration", "float", "seconds to wait before succeeding; 0 waits until the state is left", default=0.0),
        doc="stand still",
        implementation="alica.skills.navigation:Idle",
    )


def _manipulation(registry: SkillRegistry) -> None:
    steps = "alica.skills.arm_steps"
    registry.declare(
        "AlignWithObject",
        _p("object", "object", "the object to align with"),
        _p(
            "standoff",
            "float",
            "distance in metres from the object to the centre of the robot base after aligning; "
            "by default where the arm reaches best (0.55 m ahead of the arm's mount: 0.73 m for Stummel)",
            required=False,
        ),
        _p("tolerance", "float", "position tolerance in metres", default=0.02),
        doc="drive to a stand-off point facing an object, so that the arm can reach it",
        capabilities=("base",),
        implementation=f"{steps}:AlignWithObject",
    )
    registry.declare(
        "Grasp",
        _p("object", "object", "the object to grasp"),
        _p("force", "float", "finger force in newtons", default=10.0),
        doc="plan and execute a grasp of an object and close the fingers; counts the attempts as attempts(self)",
        capabilities=("arm", "gripper"),
        implementation=f"{steps}:Grasp",
    )
    registry.declare(
        "MoveArmToTransport",
        doc="move the arm, with what it holds, into its transport (home) pose",
        capabilities=("arm",),
        implementation=f"{steps}:MoveArmToTransport",
    )
    registry.declare(
        "ValidateGrip",
        _p("min_force", "float", "smallest finger force in newtons that counts as holding", default=2.0),
        doc="check by finger force that the object is still held",
        capabilities=("gripper",),
        implementation=f"{steps}:ValidateGrip",
    )
    registry.declare(
        "MoveArmToPlace",
        _p(
            "target",
            "position",
            "where to place: a position, an area such as pos(g) (a free spot in it), "
            "or a block; by default a free spot in front of the robot",
            required=False,
        ),
        doc="move the held object to its place pose (driving there first when it is out of reach)",
        capabilities=("base", "arm"),
        implementation=f"{steps}:MoveArmToPlace",
    )
    registry.declare(
        "OpenGripper",
        doc="open the fingers and let go of what they hold",
        capabilities=("gripper",),
        implementation=f"{steps}:OpenGripper",
    )
    registry.declare(
        "VerifyPlaced",
        _p("object", "object", "the object that was put down"),
        _p(
            "target",
            "position",
            "where it should lie (a position, or an area such as pos(g)); by default anywhere on the ground",
            required=False,
        ),
        doc="check that the gripper is empty and, with a look of the robot's camera, that the object lies at its place",
        capabilities=("gripper",),
        implementation=f"{steps}:VerifyPlaced",
    )
    registry.declare(
        "RandomBlockSkill",
        _p(
            "blocking_radius",
            "float",
            "a stack with another robot's centre closer than this many metres is left alone "
            "(a robot working at a stack stands about 0.7 m from it)",
            default=1.0,
        ),
        _p(
            "pause",
            "float",
            "simulated seconds to wait after each action, and between looks when nothing is applicable",
            default=2.0,
        ),
        _p(
            "action_timeout", "float", "simulated seconds after which an action still running is stopped", default=120.0
        ),
        _p(
            "step_aside",
            "float",
            "after each action, drive to a free place at least this many metres from every block (0: stay)",
            default=1.15,
        ),
        doc="opponent: run a random applicable blocks-world skill on a stack no other robot is blocking, forever",
        capabilities=("base", "arm", "gripper"),
        implementation="alica.skills.opponent:RandomBlockSkill",
    )


def _directed_vision(registry: SkillRegistry) -> None:
    registry.declare(
        "DetectCircles",
        _p("radius", "float", "radius in metres of the drill samples to look for", default=0.03),
        _p("tolerance", "float", "allowed radius error in metres (plus half a ray spacing at the range)", default=0.01),
        _p("max_range", "float", "farthest distance in metres to consider", default=8.0),
        _p(
            "wait",
            "float",
            "seconds to keep scanning for an unverified candidate within max_range before failing "
            "(0: fail at once when the scan has no circle; inf: until one is found)",
            default=0.0,
        ),
        _p("period", "float", "seconds between two scans while waiting", default=0.5),
        _p(
            "n_rays",
            "int",
            "rays of the scan over the full circle (1440: 0.25 degrees, a Hokuyo UTM-30LX)",
            default=1440,
        ),
        doc="find circular shapes of the sample radius in the 2D laser scan and report them as candidates",
        capabilities=("lidar2d",),
        implementation="alica.skills.vision2d:DetectCircles",
    )
    registry.declare(
        "CropCandidate",
        _p("margin", "float", "extra border around the candidate in metres", default=0.1),
        _p(
            "max_range",
            "float",
            "farthest candidate in metres to look at (blob detection works at short range)",
            default=5.0,
        ),
        _p(
            "retry",
            "float",
            "seconds a candidate the camera could not see comes after the others",
            default=5.0,
        ),
        _p("width", "int", "camera image width in pixels (752: Scout's Guppy camera)", default=752),
        _p("height", "int", "camera image height in pixels", default=480),
        doc="turn the camera (pan unit) to the nearest unverified candidate, project it into the image and crop it",
        capabilities=("camera",),
        implementation="alica.skills.vision2d:CropCandidate",
    )
    registry.declare(
        "BlobDetect",
        _p("colours", "list", "colours to search for (green, red, blue, yellow)", default=("green", "red")),
        _p("min_area", "int", "smallest blob in pixels", default=12),
        doc="find coloured blobs in the cropped candidate image (short range only)",
        capabilities=("camera",),
        implementation="alica.skills.vision2d:BlobDetect",
    )
    registry.declare(
        "ClassifySample",
        _p("min_confidence", "float", "lowest confidence in [0, 1] that counts as a sample", default=0.3),
        doc="decode the sample from its upper, middle and lower sections (green/red, black/white, green/red)",
        capabilities=("camera",),
        implementation="alica.skills.vision2d:ClassifySample",
    )


def _semantic_perception(registry: SkillRegistry) -> None:
    module = "alica.skills.semantic_perception"
    registry.declare(
        "StereoPointCloud",
        _p("max_depth", "float", "points farther than this many metres are dropped", default=3.0),
        _p("width", "int", "width in pixels of the depth image", default=640),
        _p("height", "int", "height in pixels of the depth image", default=480),
        _p("median", "int", "side in pixels of the median filter on the depth image (1: none)", default=3),
        doc="compute a 3D point cloud from the stereo camera's depth image into scratch['cloud']",
        capabilities=("stereo_camera",),
        implementation=f"{module}:StereoPointCloud",
    )
    registry.declare(
        "RansacGroundPlane",
        _p("distance_threshold", "float", "largest point-to-plane distance in metres of an inlier", default=0.02),
        _p("iterations", "int", "RANSAC iterations", default=500),
        _p("max_tilt", "float", "largest angle in degrees between the plane's normal and up", default=30.0),
        _p("min_inliers", "float", "smallest fraction of the cloud the plane must hold", default=0.1),
        doc="fit the ground plane with RANSAC and remove its points from the cloud",
        capabilities=("stereo_camera",),  # a step of the pipeline on the stereo cloud: it runs where the cloud is
        implementation=f"{module}:RansacGroundPlane",
    )
    registry.declare(
        "EuclideanCluster",
        _p("tolerance", "float", "largest distance in metres between neighbouring points of a cluster", default=0.03),
        _p("min_points", "int", "smallest cluster kept", default=50),
        _p("max_points", "int", "largest cluster kept (0: no limit)", default=0),
        doc="split the remaining points into clusters of nearby points",
        capabilities=("stereo_camera",),  # a step of the pipeline on the stereo cloud: it runs where the cloud is
        implementation=f"{module}:EuclideanCluster",
    )
    registry.declare(
        "FitModel",
        _p("model", "str", "geometric model of the object", default="cylinder"),
        _p(
            "axis",
            "str",
            "cylinder axis: 'plane' (the ground's normal) or 'pca' (the cluster's main axis)",
            default="plane",
        ),
        doc="fit the sample's geometric model to every cluster and extract its features",
        capabilities=("stereo_camera",),  # a step of the pipeline on the stereo cloud: it runs where the cloud is
        implementation=f"{module}:FitModel",
    )
    registry.declare(
        "FuzzyDLClassify",
        _p(
            "knowledge_base",
            "str",
            "fuzzy description of the objects (radius, height, orientation)",
            default="drill_sample",
        ),
        _p("threshold", "float", "smallest degree of membership that counts as a match", default=0.6),
        _p("tnorm", "str", "fuzzy conjunction of the memberships: min, product or lukasiewicz", default="min"),
        _p("match_radius", "float", "metres within which a detection is a sample the world model knows", default=0.3),
        _p(
            "retract_range",
            "float",
            "metres within which a found sample in clear view that is not seen again is retracted (0: never)",
            default=2.0,
        ),
        doc="rate the fitted clusters against the fuzzy object description and report found(s), onground(s), pos(s), confidence(s)",
        capabilities=("stereo_camera",),  # a step of the pipeline on the stereo cloud: it runs where the cloud is
        implementation=f"{module}:FuzzyDLClassify",
    )
    registry.declare_function("confidence", 1, "confidence(s): degree in [0, 1] to which sample s was recognised")


def _facts(registry: SkillRegistry) -> None:
    """The facts the implemented skills write to the world model, so any plan may read them undeclared."""
    registry.declare_predicate("holding", 2, "holding(r, x): robot r holds object x (Pickup, Unstack, Putdown, Stack)")
    registry.declare_predicate("handempty", 1, "handempty(r): robot r holds nothing")
    registry.declare_predicate("onground", 1, "onground(x): object x lies on the ground (Putdown; a detected sample)")
    registry.declare_predicate("on", 2, "on(x, y): block x stands on block y (Stack, Unstack; blocks-world perception)")
    registry.declare_predicate("ontable", 1, "ontable(x): block x stands on the table (Putdown)")
    registry.declare_predicate("clear", 1, "clear(x): nothing stands on block x")
    registry.declare_function(
        "pos",
        1,
        "pos(x): the position [x, y] a robot reached (MoveToPosition), or where sample x was found "
        "(ClassifySample, FuzzyDLClassify)",
    )
    registry.declare_function("attempts", 1, "attempts(r): grasp attempts of robot r so far (Pickup)")
    registry.declare_predicate(
        "candidate",
        1,
        "candidate(c): a circle of the sample radius seen by the laser, not yet verified (DetectCircles)",
    )
    registry.declare_predicate(
        "invalid", 1, "invalid(c): a closer look found candidate c is no sample (BlobDetect, ClassifySample)"
    )
    registry.declare_function(
        "candidate_pos", 1, "candidate_pos(c): the position [x, y] of candidate c (DetectCircles)"
    )
    registry.declare_function(
        "found_at",
        1,
        "found_at(s): when sample s was first found, in simulated seconds (ClassifySample, FuzzyDLClassify)",
    )
    registry.declare_function(
        "sample_kind", 1, "sample_kind(s): the kind of sample s, e.g. green-black-red (ClassifySample)"
    )


def declare_all(registry: SkillRegistry) -> None:
    """Declare every skill the shipped plans use.

    Args:
        registry: the registry to add the declarations to.

    Raises:
        ValueError: a skill of the same name is already registered.
    """
    _composite(registry)
    _navigation(registry)
    _manipulation(registry)
    _directed_vision(registry)
    _facts(registry)
    _semantic_perception(registry)


def register(registry: SkillRegistry) -> None:
    """The plug-in entry point of the shipped catalogue: :func:`declare_all`."""
    declare_all(registry)
