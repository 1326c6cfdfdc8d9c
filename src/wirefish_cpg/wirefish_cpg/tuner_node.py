"""
tuner_node: fits the CPG to a desired body wave on request (paper section 4, eqs 23-27).

Service
    ``retune_gait`` (wirefish_msgs/srv/RetuneGait). The request is validated (finite values,
    frequency in (0, 10] Hz, k > 0, swarm_size 0 or in [2, 2000], max_iterations 0 or in
    [1, 5000]; 0 = this node's default) and answered with ``success: false`` and the reason
    otherwise. One fit runs at a time: a request arriving while one runs is refused at once
    with ``success: false`` ("busy"), not queued. With ``apply: true`` the fitted parameters
    are set on the CPG node through its standard ``<cpg_node_name>/set_parameters_atomically``
    service (the same change as ``ros2 param set``), and success is reported only after the
    CPG node accepted them. Offsets are not touched (the fit assumes b = 0).
Publishes
    ``retune_progress`` (std_msgs/Float64MultiArray, reliable, depth 10) while a fit runs, once
    per PSO iteration: ``data = [iteration, best_loss (m*s), max_iterations]``; iteration 0 is
    the initial swarm, and the run can end before max_iterations when the loss stalls.
    ``target_wave`` (wirefish_msgs/BodyWaveSpec, reliable, transient local, depth 1): the wave
    of each accepted request.
The fit runs in the service callback on a multi-threaded executor; the service and the
parameter client sit in separate callback groups, so the node keeps serving (parameters,
refusals, the parameter-service response) while a fit runs.
"""

from __future__ import annotations

import math
import threading

import numpy as np
from rcl_interfaces.msg import Parameter as ParameterMsg, SetParametersResult
from rcl_interfaces.srv import SetParametersAtomically
import rclpy
from rclpy.callback_groups import MutuallyExclusiveCallbackGroup, ReentrantCallbackGroup
from rclpy.executors import ExternalShutdownException, MultiThreadedExecutor
from rclpy.node import Node
from rclpy.parameter import Parameter
from rclpy.qos import DurabilityPolicy, QoSProfile, ReliabilityPolicy
from rclpy.signals import SignalHandlerOptions
from std_msgs.msg import Float64MultiArray
from wirefish_common.parameter_table import (create_node_or_exit, declare, ParameterSpec,
                                             validate_update)
from wirefish_common.shutdown import SignalShutdown
from wirefish_cpg.cpg_messages import to_message
from wirefish_cpg.oscillator import CpgParameters
from wirefish_cpg.pso import PsoOptions
from wirefish_cpg.tuning import fit_gait
from wirefish_cpg.wave_loss import WaveFitProblem, WaveSpec
from wirefish_kinematics.geometry import FishGeometry
from wirefish_kinematics.node_parameters import BODY_WAVE_GEOMETRY_FIELDS, geometry_parameters
from wirefish_msgs.msg import BodyWaveSpec
from wirefish_msgs.srv import RetuneGait

# The fit needs the body wave's geometry only; its specs are the one geometry block's.
GEOMETRY_FIELDS = BODY_WAVE_GEOMETRY_FIELDS
TUNER_PARAMETERS = (
    ParameterSpec('cpg_node_name', 'cpg_node',
                  'Name (relative or absolute) of the CPG node whose parameters apply sets'),
    ParameterSpec('swarm_size', 40, 'Default PSO particles per run', 2, 2000),
    ParameterSpec('max_iterations', 100, 'Default PSO iteration limit', 1, 5000),
    ParameterSpec('stall_iterations', 20, 'Stop after this many iterations without gain', 1,
                  5000),
    ParameterSpec('stall_tolerance', 1e-6, 'Relative gain below which an iteration stalls',
                  0.0, 1.0),
    ParameterSpec('inertia', 0.7298, 'PSO inertia weight c_w, eq 26', 0.0, 2.0),
    ParameterSpec('cognitive', 1.49618, 'PSO learning factor c_f1, eq 26', 0.0, 4.0),
    ParameterSpec('social', 1.49618, 'PSO learning factor c_f2, eq 26', 0.0, 4.0),
    ParameterSpec('weight_bound', 10.0, 'Search bound |w_ij| (1/s); paper: 10', 0.0, 10.0,
                  low_exclusive=True),
    ParameterSpec('phase_bound', math.pi, 'Search bound |phi_ij| (rad); paper: pi', 0.0,
                  math.pi, low_exclusive=True),
    ParameterSpec('amplitude_bound', math.pi / 2, 'Search bound |R_i| (rad); paper: pi/2',
                  0.0, math.pi / 2, low_exclusive=True),
    ParameterSpec('alpha', 20.0, 'Convergence gain alpha given to fitted gaits (1/s)', 0.0,
                  200.0, low_exclusive=True),
    ParameterSpec('samples_per_period', 48, 'Quadrature points of the loss per period', 8,
                  2000),
    ParameterSpec('apply_timeout_s', 5.0, 'Wait for the CPG node to accept (s)', 0.1, 60.0),
) + geometry_parameters(GEOMETRY_FIELDS)
SPECS = {spec.name: spec for spec in TUNER_PARAMETERS}
LATCHED = QoSProfile(depth=1, reliability=ReliabilityPolicy.RELIABLE,
                     durability=DurabilityPolicy.TRANSIENT_LOCAL)
RELIABLE = QoSProfile(depth=10, reliability=ReliabilityPolicy.RELIABLE)


def request_problem(request: RetuneGait.Request) -> str | None:
    """Return why a RetuneGait request is invalid, or None if it is acceptable."""
    wave = request.wave
    values = {'c1': wave.c1, 'c2': wave.c2, 'k': wave.k, 'frequency_hz': wave.frequency_hz}
    for name, value in values.items():
        if not math.isfinite(value):
            return f'wave.{name} must be finite, got {value}'
    if not 0.0 < wave.frequency_hz <= 10.0:
        return f'wave.frequency_hz must be in (0, 10] Hz, got {wave.frequency_hz:g}'
    if wave.k <= 0.0:
        return f'wave.k must be > 0, got {wave.k:g}'
    if request.swarm_size != 0 and not 2 <= request.swarm_size <= 2000:
        return f'swarm_size must be 0 (default) or in [2, 2000], got {request.swarm_size}'
    if request.max_iterations != 0 and not 1 <= request.max_iterations <= 5000:
        return (f'max_iterations must be 0 (default) or in [1, 5000], '
                f'got {request.max_iterations}')
    return None


def parameter_messages(params: CpgParameters) -> list[ParameterMsg]:
    """Return the CPG node parameters a fit sets (all but the offsets), as messages."""
    values = {'frequency_hz': params.frequency_hz, 'amplitude_1': params.amplitude[0],
              'amplitude_2': params.amplitude[1], 'w12': params.w12, 'w21': params.w21,
              'phi12': params.phi12, 'phi21': params.phi21, 'alpha': params.alpha}
    return [Parameter(name, Parameter.Type.DOUBLE, float(value)).to_parameter_msg()
            for name, value in values.items()]


class TunerNode(Node):
    """Serves retune_gait: PSO fit of the CPG to a body wave, optionally applied."""

    def __init__(self, **kwargs) -> None:
        """Declare the parameters; wire the service, publishers and the parameter client."""
        super().__init__('tuner_node', **kwargs)
        declare(self, TUNER_PARAMETERS)
        self.add_on_set_parameters_callback(self._validate)
        self._busy = threading.Lock()
        self._progress_pub = self.create_publisher(Float64MultiArray, 'retune_progress',
                                                   RELIABLE)
        self._wave_pub = self.create_publisher(BodyWaveSpec, 'target_wave', LATCHED)
        self._client_group = MutuallyExclusiveCallbackGroup()
        self._param_clients: dict[str, object] = {}
        self.create_service(RetuneGait, 'retune_gait', self._on_retune,
                            callback_group=ReentrantCallbackGroup())

    def _validate(self, parameters: list[Parameter]) -> SetParametersResult:
        return validate_update(SPECS, {}, parameters)

    def _value(self, name: str):
        return self.get_parameter(name).value

    def _parameter_client(self):
        service = f'{self._value("cpg_node_name")}/set_parameters_atomically'
        if service not in self._param_clients:
            self._param_clients[service] = self.create_client(
                SetParametersAtomically, service, callback_group=self._client_group)
        return self._param_clients[service]

    def _on_retune(self, request: RetuneGait.Request, response: RetuneGait.Response
                   ) -> RetuneGait.Response:
        reason = request_problem(request)
        if reason is not None:
            response.success, response.message = False, f'rejected: {reason}'
            return response
        if not self._busy.acquire(blocking=False):
            response.success = False
            response.message = 'busy: a retune is already running; retry when it finishes'
            return response
        try:
            self._wave_pub.publish(request.wave)
            return self._retune(request, response)
        except ValueError as error:  # e.g. a geometry FishGeometry refuses
            response.success, response.message = False, f'rejected: {error}'
            return response
        except Exception as error:  # noqa: B902 (answer, and keep serving, whatever failed)
            self.get_logger().error(f'retune failed: {error!r}')
            response.success, response.message = False, f'failed: {error!r}'
            return response
        finally:
            self._busy.release()

    def _retune(self, request: RetuneGait.Request, response: RetuneGait.Response
                ) -> RetuneGait.Response:
        wave = request.wave
        geometry = FishGeometry(**{name: self._value(name) for name in GEOMETRY_FIELDS})
        problem = WaveFitProblem(
            wave=WaveSpec(wave.c1, wave.c2, wave.k, wave.frequency_hz), geometry=geometry,
            samples_per_period=self._value('samples_per_period'))
        options = PsoOptions(
            swarm_size=request.swarm_size or self._value('swarm_size'),
            max_iterations=request.max_iterations or self._value('max_iterations'),
            inertia=self._value('inertia'), cognitive=self._value('cognitive'),
            social=self._value('social'), stall_iterations=self._value('stall_iterations'),
            stall_tolerance=self._value('stall_tolerance'))
        upper = np.array([self._value('weight_bound')] * 2 + [self._value('phase_bound')] * 2
                         + [self._value('amplitude_bound')] * 2)

        def progress(iteration: int, best_loss: float, _position: np.ndarray) -> None:
            self._progress_pub.publish(Float64MultiArray(
                data=[float(iteration), best_loss, float(options.max_iterations)]))

        fit = fit_gait(problem, np.random.default_rng(request.seed), options, -upper, upper,
                       alpha=self._value('alpha'), callback=progress)
        response.params = to_message(fit.params)
        response.loss = fit.loss
        response.rmse_theta_deg = [float(v) for v in fit.rmse_theta_deg]
        response.iterations = fit.iterations
        response.elapsed_s = fit.elapsed_s
        summary = (f'loss {fit.loss:.6g} m*s after {fit.iterations} iterations, RMSE theta '
                   f'{fit.rmse_theta_deg[0]:.3f}/{fit.rmse_theta_deg[1]:.3f} deg')
        if not request.apply:
            response.success, response.message = True, f'fitted: {summary}'
            return response
        reason = self._apply(fit.params)
        response.success = reason is None
        response.message = (f'fitted and applied: {summary}' if reason is None
                            else f'fitted ({summary}) but not applied: {reason}')
        return response

    def _apply(self, params: CpgParameters) -> str | None:
        """Set the fit on the CPG node atomically; return why it failed, or None."""
        client = self._parameter_client()
        timeout = self._value('apply_timeout_s')
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


def main(args: list[str] | None = None) -> None:
    """Run the tuner node on a multi-threaded executor until shutdown."""
    signals = SignalShutdown()  # Ctrl-C between callbacks: see wirefish_common.shutdown
    rclpy.init(args=args, signal_handler_options=SignalHandlerOptions.NO)
    node = create_node_or_exit(TunerNode)
    signals.attach(node)
    executor = MultiThreadedExecutor(num_threads=4)
    executor.add_node(node)
    try:
        executor.spin()
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()
