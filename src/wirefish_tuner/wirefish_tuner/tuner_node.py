# SPDX-License-Identifier: Apache-2.0
"""
tuner_node: fits the CPG to a desired body wave on request (paper section 4, eqs 23-27).

Service ``retune_gait`` (wirefish_msgs/srv/RetuneGait) and action ``retune_gait``
(wirefish_msgs/action/RetuneGait) share one fitting core (``wirefish_tuner.retune_core``) and
one busy lock: one fit at a time. Every order is judged (values; whether the tail can follow
the wave at all, ``wirefish_tuner.feasibility``), fitted, and the fit judged (finite loss,
swing-angle RMSE <= ``max_rmse_deg``); a refused wave or fit answers ``success: false`` with
the reason and the figures and is never applied. With ``apply: true`` the fitted parameters are
set on the CPG node through its standard ``<cpg_node_name>/set_parameters_atomically`` service
(the same change as ``ros2 param set``), and success is reported only after the CPG node
accepted them. Offsets are not touched (the fit assumes b = 0). An applied fit is the CPG's
manual override (``wirefish_cpg.cpg_control``): the planner stands aside until
``cpg_node/follow_commands``. The tuner keeps this atomic parameter set rather than the
planner's control topic: a fit is a one-off configuration change that must be confirmed.

Service: every request is answered, however many arrive at once: the service keeps up to 1000
requests (``SERVICE_QOS``), answers are paced 20 ms apart so that no client's answer is pushed
out of its queue by the others' (``answered_service``), and a request during a fit is refused
at once ("busy"), not queued. The service always fits (same seed, same result) and does not
read the library.
Action: feedback after the initial swarm and every PSO iteration (iteration, best loss, RMSE of
the best so far); cancel stops the fit before the next iteration and applies nothing; a goal
sent during a fit (from either) is REJECTED at once; ``use_library`` (default true) answers a
wave the library holds for this geometry without fitting.
Gait library (``library_path``, ``wirefish_cpg.gait_library``): every successful fit is stored
(YAML, atomic write, merged with what other writers added); read at start-up and whenever the
file changes.
Publishes ``target_wave`` (wirefish_msgs/BodyWaveSpec, reliable, transient local, depth 1):
the wave the CPG runs, only once a fit was applied.
On simulated time the node's /clock is taken on ``tuner_node_clock``, a companion node on a
thread of its own (``wirefish_common.clock_feed``): every tick woke the multi-threaded executor.
"""

from __future__ import annotations

from pathlib import Path
import threading

from rcl_interfaces.msg import Parameter as ParameterMsg
from rcl_interfaces.srv import SetParametersAtomically
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup
from rclpy.executors import MultiThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from wirefish_common.clock_feed import ClockFeed
from wirefish_common.node_main import run_node
from wirefish_common.parameter_table import NodeParameters
from wirefish_common.qos import LATCHED, latched, reliable
from wirefish_cpg.cpg_messages import to_message
from wirefish_cpg.gait_library import Gait, GaitLibrary, LibraryFile
from wirefish_cpg.oscillator import CpgParameters
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.geometry_parameters import BODY_WAVE_GEOMETRY_FIELDS
from wirefish_msgs.action import RetuneGait as RetuneGaitAction
from wirefish_msgs.msg import BodyWaveSpec
from wirefish_msgs.srv import RetuneGait
from wirefish_tuner.answered_service import paced
from wirefish_tuner.feasibility import FitLimits
from wirefish_tuner.pso import PsoOptions
from wirefish_tuner.retune_core import (FitCancelled, gait_of, retune, RetuneOrder, RetuneOutcome,
                                        RetuneProgress, RetuneSettings)
from wirefish_tuner.tuner_node_parameters import TABLE

# A burst of requests must fit the service's own DDS queues while a fit holds the executor;
# its clients' queues are protected by pacing the answers (answered_service).
SERVICE_QOS = reliable(depth=1000)
# Feedback of every iteration (hundreds per second) must not overwrite itself in the writer's
# history before a client takes it; a client keeps what its own depth allows (rclpy: 10).
# Transient local: a client's feedback reader made just before its goal (wirefish retune's
# GoalSender) may be matched by this writer only after the first iterations, or the whole of a
# short fit, were published; a volatile writer never sends those (seen: a 5-iteration goal
# succeeded and its new reader heard none of its 6 feedbacks). A reader asking for transient
# local gets the last 1000 when it matches; a volatile one (rclpy's ActionClient) what follows.
FEEDBACK_QOS = latched(depth=1000)
BUSY = 'busy: a retune is already running; retry when it finishes'
CANCELED = 'canceled: nothing applied'


def order_of(request, use_library: bool = False) -> RetuneOrder:
    """Return the retune order of a service request or action goal (same fields)."""
    wave = request.wave
    return RetuneOrder(c1=wave.c1, c2=wave.c2, k=wave.k, frequency_hz=wave.frequency_hz,
                       seed=request.seed, max_iterations=request.max_iterations,
                       swarm_size=request.swarm_size, use_library=use_library,
                       mode=request.mode)


def parameter_messages(params: CpgParameters) -> list[ParameterMsg]:
    """Return the CPG node parameters a fit sets (all but the offsets), as messages."""
    values = {'frequency_hz': params.frequency_hz, 'amplitude_1': params.amplitude[0],
              'amplitude_2': params.amplitude[1], 'w12': params.w12, 'w21': params.w21,
              'phi12': params.phi12, 'phi21': params.phi21, 'alpha': params.alpha}
    return [Parameter(name, Parameter.Type.DOUBLE, float(value)).to_parameter_msg()
            for name, value in values.items()]


class TunerNode(Node):
    """Serves the retune_gait service and action: PSO fits of the CPG to a body wave."""

    def __init__(self, **kwargs) -> None:
        """Declare the parameters; wire the service, the action, publishers, the library."""
        super().__init__('tuner_node', **kwargs)
        self._node_parameters = NodeParameters(self, TABLE, self._on_parameters_set)
        self._busy = threading.Lock()  # one fit at a time, service or action
        self._library = LibraryFile(self._library_path())
        self._load_library()
        self._wave_pub = self.create_publisher(BodyWaveSpec, 'target_wave', LATCHED)
        self._client_group = MutuallyExclusiveCallbackGroup()
        self._param_clients: dict[str, object] = {}
        serving = ReentrantCallbackGroup()
        self.create_service(RetuneGait, 'retune_gait', paced(self._on_retune),
                            qos_profile=SERVICE_QOS, callback_group=serving)
        self._action = ActionServer(
            self, RetuneGaitAction, 'retune_gait', execute_callback=self._execute_goal,
            goal_callback=self._on_goal, cancel_callback=lambda _goal: CancelResponse.ACCEPT,
            callback_group=serving, feedback_pub_qos_profile=FEEDBACK_QOS)
        # The multi-threaded executor woken by every /clock tick took most of a core.
        self._clock_feed = ClockFeed.start(self)

    def destroy_node(self) -> None:
        """Stop the clock feed, destroy the action server, then the node."""
        if self._clock_feed is not None:
            self._clock_feed.close()
        self._action.destroy()
        super().destroy_node()

    def _on_parameters_set(self, names: frozenset[str]) -> None:
        if 'library_path' in names:
            self._library = LibraryFile(self._library_path())
            self._load_library()

    def _library_path(self) -> Path:
        return Path(self._node_parameters.str_value('library_path'))

    def _load_library(self) -> None:
        try:
            count = len(self._library.current().gaits)
        except (OSError, ValueError) as error:
            self.get_logger().error(f'gait library unreadable, not used: {error}')
            return
        self.get_logger().info(f'gait library {self._library.path}: {count} gaits')

    def _settings(self) -> RetuneSettings:
        """Return the fit settings of the current parameters (raises ValueError if invalid)."""
        value, count = self._node_parameters.float_value, self._node_parameters.int_value
        return RetuneSettings(
            geometry=FishGeometry(**{name: value(name) for name in BODY_WAVE_GEOMETRY_FIELDS}),
            limits=FitLimits(servo_range_rad=value('amplitude_bound'),
                             servo_rate_limit_rad_s=value('servo_rate_limit_rad_s'),
                             min_frequency_hz=value('min_frequency_hz'),
                             max_rmse_deg=value('max_rmse_deg')),
            pso=PsoOptions(swarm_size=count('swarm_size'),
                           max_iterations=count('max_iterations'), inertia=value('inertia'),
                           cognitive=value('cognitive'), social=value('social'),
                           stall_iterations=count('stall_iterations'),
                           stall_tolerance=value('stall_tolerance')),
            upper=(value('weight_bound'),) * 2 + (value('phase_bound'),) * 2
            + (value('amplitude_bound'),) * 2,
            alpha=value('alpha'), samples_per_period=count('samples_per_period'))

    def _parameter_client(self):
        name = self._node_parameters.str_value('cpg_node_name')
        service = f'{name}/set_parameters_atomically'
        if service not in self._param_clients:
            self._param_clients[service] = self.create_client(
                SetParametersAtomically, service, callback_group=self._client_group)
        return self._param_clients[service]

    def _on_retune(self, request: RetuneGait.Request, response: RetuneGait.Response
                   ) -> RetuneGait.Response:
        if not self._busy.acquire(blocking=False):
            response.success = False
            response.message = BUSY
            return response
        try:
            outcome, success, message, _applied = self._serve(order_of(request),
                                                              request.apply, request.wave)
        except Exception as error:  # noqa: B902 (answer, and keep serving, whatever failed)
            self.get_logger().error(f'retune failed: {error!r}')
            response.success, response.message = False, f'failed: {error!r}'
            return response
        finally:
            self._busy.release()
        fill_response(response, outcome)
        response.success, response.message = success, message
        return response

    def _on_goal(self, _goal: RetuneGaitAction.Goal) -> GoalResponse:
        # Documented: a goal during a fit is rejected at once (the client sees accepted false);
        # an accepted goal holds the busy lock until its execution ends.
        return GoalResponse.ACCEPT if self._busy.acquire(blocking=False) else GoalResponse.REJECT

    def _execute_goal(self, goal_handle) -> RetuneGaitAction.Result:
        goal = goal_handle.request
        result = RetuneGaitAction.Result()
        try:
            order = order_of(goal, use_library=goal.use_library)
            limit = (order.max_iterations
                     or self._node_parameters.int_value('max_iterations'))

            def progress(iteration: int, best_loss: float, rmse) -> None:
                if goal_handle.is_cancel_requested:
                    raise FitCancelled(iteration)
                goal_handle.publish_feedback(RetuneGaitAction.Feedback(
                    iteration=iteration, max_iterations=limit, best_loss=float(best_loss),
                    rmse_theta_deg=[float(v) for v in rmse]))

            outcome, success, message, applied = self._serve(
                order, goal.apply, goal.wave, progress,
                cancelled=lambda: goal_handle.is_cancel_requested)
            fill_response(result, outcome)
            result.success, result.message, result.applied = success, message, applied
            result.from_library = outcome.from_library
            if message == CANCELED and not applied:
                goal_handle.canceled()
            elif success:
                goal_handle.succeed()
            else:
                goal_handle.abort()
        except FitCancelled as stop:
            result.success, result.message = False, f'{CANCELED} at iteration {stop.args[0]}'
            goal_handle.canceled()
        except Exception as error:  # noqa: B902 (answer, and keep serving, whatever failed)
            self.get_logger().error(f'retune goal failed: {error!r}')
            result.success, result.message = False, f'failed: {error!r}'
            goal_handle.abort()
        finally:
            self._busy.release()
        return result

    def _serve(self, order: RetuneOrder, apply: bool, wave: BodyWaveSpec,
               progress: RetuneProgress | None = None,
               cancelled=lambda: False) -> tuple[RetuneOutcome, bool, str, bool]:
        """
        Run one order through the core; store a new fit; apply it if asked.

        Returns (outcome, success, message, applied); ``FitCancelled`` from ``progress``
        propagates. A cancel that arrives after the fit but before applying still cancels.
        """
        settings = self._settings()
        library = self._library_now() if order.use_library else None
        outcome = retune(order, settings, progress, library)
        if outcome.success and not outcome.from_library:
            self._store(gait_of(order, outcome, settings))
        if not outcome.success:
            return outcome, False, outcome.message, False
        if cancelled():
            return outcome, False, CANCELED, False
        if not apply:
            return outcome, True, outcome.message, False
        assert outcome.params is not None  # retune's every successful outcome carries its fit
        reason = self._apply(outcome.params)
        fitted = outcome.message if outcome.from_library else f'fitted ({outcome.summary()})'
        if reason is not None:
            return outcome, False, f'{fitted} but not applied: {reason}', False
        self._wave_pub.publish(wave)  # the wave the CPG now runs (kinematics overlay)
        applied = (f'{outcome.message}; applied' if outcome.from_library
                   else f'fitted and applied: {outcome.summary()}')
        return outcome, True, applied, True

    def _library_now(self) -> GaitLibrary | None:
        try:
            return self._library.current()
        except (OSError, ValueError) as error:
            self.get_logger().warning(f'gait library unreadable, fitting instead: {error}')
            return None

    def _store(self, gait: Gait) -> None:
        try:
            self._library.add([gait])
        except (OSError, ValueError) as error:
            self.get_logger().warning(f'fit not stored in the gait library: {error}')

    def _apply(self, params: CpgParameters) -> str | None:
        """Set the fit on the CPG node atomically; return why it failed, or None."""
        client = self._parameter_client()
        timeout = self._node_parameters.float_value('apply_timeout_s')
        if not client.wait_for_service(timeout_sec=timeout):
            return f'no service {client.srv_name} within {timeout:g} s'
        done = threading.Event()
        future = client.call_async(
            SetParametersAtomically.Request(parameters=parameter_messages(params)))
        future.add_done_callback(lambda _future: done.set())
        if not done.wait(timeout):
            future.cancel()
            return f'{client.srv_name} did not answer within {timeout:g} s'
        result = future.result().result
        if not result.successful:
            return f'the CPG node refused: {result.reason}'
        return None


def fill_response(response, outcome: RetuneOutcome) -> None:
    """Copy an outcome's figures into a service response or action result."""
    if outcome.params is not None:
        response.params = to_message(outcome.params)
    response.loss = float(outcome.loss)
    response.rmse_theta_deg = [float(v) for v in outcome.rmse_theta_deg]
    response.iterations = outcome.iterations
    response.elapsed_s = outcome.elapsed_s


def main(args: list[str] | None = None) -> None:
    """Run the tuner node on a multi-threaded executor until shutdown."""
    run_node(TunerNode, args, executor_factory=lambda: MultiThreadedExecutor(num_threads=4))
