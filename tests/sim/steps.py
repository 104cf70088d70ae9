"""The step record after a step, built by the builders from the live run: what the recorder's
step messages are compared with (``test_records.py``, ``test_step_messages.py``)."""

from __future__ import annotations

from rsstp_format import records
from rsstp_sim import Pose, StepOutcome
from rsstp_sim.recording import builders
from rsstp_sim.transition_system import TransitionSystem


def step_record_after(
    pose: Pose, model: TransitionSystem, out: StepOutcome | None
) -> records.StepRecord | records.RoverStepRecord:
    """The step record after ``out`` (None: the reset), ending at ``pose`` with ``model`` as
    it is now, as the recorder builds it."""
    return builders.step_record(
        0 if out is None else out.step,
        pose,
        action=None if out is None else out.action,
        state_before=None if out is None else out.state_before,
        internal_state=model.current if out is None else out.state_after,
        model_version=model.version,
        no_transition=out is not None and out.no_transition,
        blocker=None if out is None else out.blocker,
    )
