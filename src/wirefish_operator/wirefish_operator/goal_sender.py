# SPDX-License-Identifier: Apache-2.0
"""
Send an action goal and get its handle even when the server's answer to it is lost.

rmw_fastrtps drops a service response ("failed to send response (timeout): client will not
receive response") when the server has not yet matched the client's response reader within
its writer's max_blocking_time (100 ms): a client that has just started, on a loaded machine,
can wait forever for the answer to a goal the server accepted and is running. An action's
goal is not a bare request, though: an accepted goal shows up in the server's status array and
in its feedback, both under the goal id the client chose. ``GoalSender`` sends the goal with
an id of its own, and when no answer comes within ``answer_wait_s`` it looks there: a goal of
its ids that is active is adopted (its result is asked for as usual); otherwise it sends the
goal again with a new id, up to ``max_sends`` times (a rejected goal never shows up, and the
resend's answer finds the reader matched by then).

The sender takes the goal's feedback from the action's feedback topic itself: rclpy forgets a
goal's feedback callback when its result arrives, and the last feedback (another topic) can
arrive after the result on a loaded machine (`wirefish retune` lost iterations 3-20 of 20
once). Keep the sender until the feedback is no longer wanted, then ``destroy()`` it. Its
feedback reader is new when the goal goes out, and the server's writer can match it only after
the first feedback was published: the reader asks for transient local, and the tuner's writer
offers it (its last 1000), so what was published before the match still arrives. A server
whose feedback is volatile never matches this reader (incompatible QoS): its goals are still
adopted from the status, but their feedback is not heard.

``goal_outcome`` is the decision, pure: what the answers and the active ids say.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
import enum
import time
from typing import Protocol, TYPE_CHECKING
import uuid

if TYPE_CHECKING:
    from rclpy.action import ActionClient
    from rclpy.action.client import ClientGoalHandle
    from rclpy.node import Node
    from rclpy.subscription import Subscription
    from rclpy.task import Future

ANSWER_WAIT_S = 3.0
MAX_SENDS = 3
# Every iteration's feedback kept (rclpy's default depth of 10 drops a fast fit's), also what
# the server published before it matched this reader: wirefish_common.qos.latched(this).
FEEDBACK_DEPTH = 1000


class GoalOutcome(enum.Enum):
    """What the answers so far say of a goal (the sender's own decision: a plain Enum)."""

    ACCEPTED = 'accepted'
    REJECTED = 'rejected'
    WAITING = 'waiting'


class _ActionMessages(Protocol):
    FeedbackMessage: type  # the action's feedback topic type (goal id and feedback)


class ActionType(Protocol):
    """An action type as rosidl generates it (e.g. ``wirefish_msgs.action.RetuneGait``)."""

    Impl: type[_ActionMessages]


def goal_outcome(answers: dict[bytes, bool | None], active: set[bytes]
                 ) -> tuple[GoalOutcome, bytes | None]:
    """
    Return (ACCEPTED, id), (REJECTED, None) or (WAITING, None) for the goals sent so far.

    ``answers``: each sent goal id (in sending order) and its answer: True accepted, False
    rejected, None none yet. ``active``: the ids the server reports running (status or
    feedback). An accepted answer wins; else an active id without an answer (its answer was
    lost); the goal is rejected only when every sent goal was answered so and none runs.
    """
    for goal_id, accepted in answers.items():
        if accepted:
            return GoalOutcome.ACCEPTED, goal_id
    for goal_id in answers:
        if goal_id in active:
            return GoalOutcome.ACCEPTED, goal_id
    if answers and all(accepted is False for accepted in answers.values()):
        return GoalOutcome.REJECTED, None
    return GoalOutcome.WAITING, None


@dataclass
class GoalSender:
    """
    One goal to an ActionClient, adopted when its answer is lost (see the module docstring).

    ``client`` is the rclpy ActionClient of ``action_type`` named ``action_name`` (relative to
    ``node``), ``spin_once`` spins the node for at most the given seconds.
    """

    node: Node
    client: ActionClient
    spin_once: Callable[[float], None]
    action_name: str
    action_type: ActionType
    answer_wait_s: float = ANSWER_WAIT_S
    max_sends: int = MAX_SENDS
    active: set[bytes] = field(default_factory=set)
    resent: int = 0
    _sent: set[bytes] = field(default_factory=set)
    _feedback_callback: Callable[[object], None] | None = None

    def __post_init__(self) -> None:
        """Subscribe to the action's status (latched: the array comes at once) and feedback."""
        from action_msgs.msg import GoalStatus, GoalStatusArray
        from rclpy.qos import qos_profile_action_status_default
        from wirefish_common.qos import latched

        running = (GoalStatus.STATUS_ACCEPTED, GoalStatus.STATUS_EXECUTING,
                   GoalStatus.STATUS_CANCELING, GoalStatus.STATUS_SUCCEEDED,
                   GoalStatus.STATUS_CANCELED, GoalStatus.STATUS_ABORTED)

        def on_status(message: GoalStatusArray) -> None:
            self.active.update(bytes(s.goal_info.goal_id.uuid) for s in message.status_list
                               if s.status in running)
        self._status: Subscription = self.node.create_subscription(
            GoalStatusArray, f'{self.action_name}/_action/status', on_status,
            qos_profile_action_status_default)

        def on_feedback(message) -> None:
            goal_id = bytes(message.goal_id.uuid)
            if goal_id in self._sent:
                self.active.add(goal_id)
                if self._feedback_callback is not None:
                    self._feedback_callback(message)
        # Every iteration's feedback kept (rclpy's default depth of 10 drops a fast fit's).
        self._feedback: Subscription = self.node.create_subscription(
            self.action_type.Impl.FeedbackMessage, f'{self.action_name}/_action/feedback',
            on_feedback, latched(FEEDBACK_DEPTH))

    def send(self, goal: object, feedback_callback: Callable[[object], None],
             deadline: float) -> ClientGoalHandle | None:
        """
        Return the goal's ClientGoalHandle (accepted or not), or None if none by ``deadline``.

        ``feedback_callback`` gets the feedback of whichever sent goal runs.
        """
        from rclpy.action.client import ClientGoalHandle
        from unique_identifier_msgs.msg import UUID

        self._feedback_callback = feedback_callback
        futures: dict[bytes, Future] = {}  # goal id -> the answer's future
        sent_at = 0.0
        while time.monotonic() < deadline:
            answers = {goal_id: (future.result().accepted if future.done() else None)
                       for goal_id, future in futures.items()}
            outcome, adopted = goal_outcome(answers, self.active)
            if outcome is GoalOutcome.ACCEPTED and adopted is not None:
                future = futures[adopted]
                if future.done():
                    return future.result()
                return ClientGoalHandle(self.client, UUID(uuid=list(adopted)),
                                        _AcceptedAnswer())
            if outcome is GoalOutcome.REJECTED:
                return next(iter(futures.values())).result()
            unanswered = not futures or answers[next(reversed(futures))] is None
            if unanswered and len(futures) < self.max_sends and (
                    not futures or time.monotonic() - sent_at >= self.answer_wait_s):
                new_id = uuid.uuid4().bytes
                self.resent += 1 if futures else 0
                self._sent.add(new_id)
                futures[new_id] = self.client.send_goal_async(
                    goal, goal_uuid=UUID(uuid=list(new_id)))
                sent_at = time.monotonic()
            self.spin_once(0.05)
        return None

    def destroy(self) -> None:
        """Drop the status and feedback subscriptions."""
        self.node.destroy_subscription(self._status)
        self.node.destroy_subscription(self._feedback)


class _AcceptedAnswer:
    """The goal answer a ClientGoalHandle holds for an adopted goal (its own was lost)."""

    accepted = True

    @property
    def stamp(self):
        from builtin_interfaces.msg import Time
        return Time()
