"""Ground truth: the world as a finite Moore machine, minimised (docs/model.md).

Joint angles are integers, so the poses reachable from the start pose are
finitely many. With a blocked move read as a self-loop, those poses and the
scenario's actions form a deterministic machine whose output in a pose is the
boolean sensation: a Moore machine. Its minimisation (partition refinement) is
the smallest internal model that predicts every sensation correctly, the
reference against which a learned model is judged (:func:`check_equivalence`).

Poses are identified by their code ``sum_i angle_i * 360**i`` (as in
:class:`~rsstp_sim.arm.world.World`). The reachable poses, their moves and their
sensations come from the scenario's :class:`~rsstp_sim.arm.table.WorldTable`
completed (breadth first, whole frontiers per vectorised batch); nothing
here loops over poses in Python.

>>> from rsstp_sim.scenario import load_scenario
>>> truth = compute_truth(load_scenario("thesis-roulette"))
>>> truth.n_poses, truth.n_sensed, truth.n_classes
(4, 1, 4)
>>> truth.class_of([180]), truth.class_next.tolist()
(2, [[1], [2], [3], [0]])
>>> check_equivalence(truth.minimal_model(), {0: True, 1: False, 2: False, 3: False}, truth)
>>> check_equivalence(truth.minimal_model(), {0: True, 1: False, 2: True, 3: False}, truth)
(0, 0)
"""

from rsstp_sim.truth._ground_truth import (
    GroundTruth,
    TruthError,
    check_equivalence,
    check_truth_size,
    compute_truth,
    format_truth,
)

__all__ = [
    "GroundTruth",
    "TruthError",
    "check_equivalence",
    "check_truth_size",
    "compute_truth",
    "format_truth",
]
