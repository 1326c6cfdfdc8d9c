# SPDX-License-Identifier: Apache-2.0
"""
The board's CPG (firmware/src/cpg.c, binary32) against wirefish_cpg's CpgIntegrator (float64).

Both integrate eq 1 with RK4 at 1 ms from rest; a parameter change swaps the targets and keeps
the state. Over 60 s with 10 parameter changes (frequencies up to 10 Hz: 3770 rad of phase)
the output angles must stay within 1e-4 rad of each other, every millisecond:

- the lone CPG of the host build (wf_host_cpg_*), stepped between the changes;
- the whole board on a simulated millisecond clock: GAIT frames through the decoder, one poll
  per ms, the servo targets after the clamp against ``clamp_to_limit`` of the Python output.

The largest errors are printed (``pytest -s``).
"""

from __future__ import annotations

import ctypes
import math

from firmware_host import CpgParams, GaitSnapshot as GaitView, LIBRARY
import numpy as np
import pytest
from wirefish_cpg.oscillator import CpgIntegrator, CpgParameters
from wirefish_cpg.servo_limit import clamp_to_limit

DURATION_MS = 60_000
CHANGES = 10
TOLERANCE_RAD = 1e-4
LIMIT = float(np.float32(1.57079625))  # the board's default servo limit (binary32 below pi/2)
GAIT, HEARTBEAT = 0x11, 0x01


class HostMsg(ctypes.Structure):
    """wf_host_msg_t: the flat message of the host build's batch codec."""

    _fields_ = [('type', ctypes.c_uint8), ('version_or_code', ctypes.c_uint8),
                ('role', ctypes.c_uint8), ('pad', ctypes.c_uint8), ('seq', ctypes.c_uint16),
                ('ref_seq_or_status', ctypes.c_uint16), ('uptime_or_time_ms', ctypes.c_uint32),
                ('f', ctypes.c_float * 12), ('pad2', ctypes.c_uint32),
                ('n', ctypes.c_int64 * 20)]


@pytest.fixture(scope='module')
def lib(firmware_build: None) -> ctypes.CDLL:
    """Return the host build with the signatures this test calls, its structures checked."""
    library = ctypes.CDLL(str(LIBRARY))
    params = ctypes.POINTER(CpgParams)
    floats = ctypes.POINTER(ctypes.c_float)
    signatures = {
        'wf_host_cpg_init': (None, [params]),
        'wf_host_cpg_set_params': (None, [params]),
        'wf_host_cpg_run': (None, [ctypes.c_uint32, floats, floats]),
        'wf_host_cpg_params_size': (ctypes.c_size_t, []),
        'wf_host_gait_snapshot_size': (ctypes.c_size_t, []),
        'wf_host_msg_size': (ctypes.c_size_t, []),
        'wf_host_reset': (None, []),
        'wf_host_set_millis': (None, [ctypes.c_uint32]),
        'wf_host_board_init': (None, [ctypes.c_void_p]),
        'wf_host_board_step': (ctypes.c_size_t, [ctypes.c_uint32, ctypes.c_char_p,
                                                 ctypes.c_size_t, ctypes.c_void_p,
                                                 ctypes.c_size_t]),
        'wf_host_board_gait': (None, [ctypes.POINTER(GaitView)]),
        'wf_host_encode_stream': (ctypes.c_size_t, [ctypes.POINTER(HostMsg), ctypes.c_size_t,
                                                    ctypes.c_char_p, ctypes.c_size_t]),
    }
    for name, (restype, argtypes) in signatures.items():
        function = getattr(library, name)
        function.restype = restype
        function.argtypes = argtypes
    assert library.wf_host_cpg_params_size() == ctypes.sizeof(CpgParams)
    assert library.wf_host_gait_snapshot_size() == ctypes.sizeof(GaitView)
    assert library.wf_host_msg_size() == ctypes.sizeof(HostMsg)
    return library


def f32(value: float) -> float:
    """Return ``value`` rounded to binary32: what a GAIT frame carries."""
    return float(np.float32(value))


def random_parameters(rng: np.random.Generator) -> CpgParameters:
    """Return valid GAIT parameters (binary32 values) across the ranges the board accepts."""
    return CpgParameters(frequency_hz=f32(rng.uniform(0.3, 10.0)),
                         amplitude=(f32(rng.uniform(0.0, 1.2)), f32(rng.uniform(0.0, 1.2))),
                         offset=(f32(rng.uniform(-0.4, 0.4)), f32(rng.uniform(-0.4, 0.4))),
                         w12=f32(rng.uniform(-1.0, 1.0)), w21=f32(rng.uniform(-1.0, 1.0)),
                         phi12=f32(rng.uniform(-math.pi, math.pi)),
                         phi21=f32(rng.uniform(-math.pi, math.pi)),
                         alpha=f32(rng.uniform(5.0, 200.0)))


def schedule(seed: int) -> list[tuple[int, CpgParameters]]:
    """Return (ms, parameters): Table 1 at 1 Hz from 0, then 10 changes at random ms."""
    rng = np.random.default_rng(seed)
    first = CpgParameters(frequency_hz=1.0, amplitude=(f32(0.38), f32(0.47)), w12=f32(-0.41),
                          w21=f32(0.64), phi12=f32(1.76), phi21=f32(1.06))
    times = np.sort(rng.choice(np.arange(1000, DURATION_MS - 1000), CHANGES, replace=False))
    return [(0, first)] + [(int(t), random_parameters(rng)) for t in times]


def to_c(params: CpgParameters) -> CpgParams:
    """Return the C structure of ``params``."""
    return CpgParams(params.frequency_hz, (ctypes.c_float * 2)(*params.amplitude),
                     (ctypes.c_float * 2)(*params.offset), params.w12, params.w21,
                     params.phi12, params.phi21, params.alpha)


def python_run(plan: list[tuple[int, CpgParameters]]) -> tuple[np.ndarray, np.ndarray]:
    """
    Return CpgIntegrator's angles and phases (DURATION_MS, 2) at 1, 2, ... ms.

    A phase is NaN where the integrator's summed float clock left its state a step short of
    the ms (``output`` then adds the partial step, so the angle is still at the ms).
    """
    integrator = CpgIntegrator(plan[0][1], step_s=1e-3)
    changes = dict(plan[1:])
    angles = np.empty((DURATION_MS, 2))
    phases = np.full((DURATION_MS, 2), np.nan)
    for k in range(1, DURATION_MS + 1):
        integrator.advance(k * 1e-3)
        angles[k - 1] = integrator.output(k * 1e-3)[0]
        if abs(integrator.time_s - k * 1e-3) < 1e-7:
            phases[k - 1] = integrator.state[0]
        if k in changes:
            integrator.set_parameters(changes[k])
    return angles, phases


def wrapped(difference: np.ndarray) -> np.ndarray:
    """Return ``difference`` (rad) wrapped to [-pi, pi)."""
    return (difference + np.pi) % (2.0 * np.pi) - np.pi


@pytest.fixture(scope='module')
def plan_and_reference() -> tuple[list[tuple[int, CpgParameters]], np.ndarray, np.ndarray]:
    """Return the parameter schedule and the float64 reference run of it."""
    plan = schedule(seed=33)
    angles, phases = python_run(plan)
    return plan, angles, phases


def test_lone_c_cpg_matches_cpg_integrator_over_60_s(lib: ctypes.CDLL, plan_and_reference):
    plan, reference, reference_phases = plan_and_reference
    angles = np.empty((DURATION_MS, 2), np.float32)
    phases = np.empty((DURATION_MS, 2), np.float32)
    lib.wf_host_cpg_init(ctypes.byref(to_c(plan[0][1])))
    bounds = [t for t, _ in plan[1:]] + [DURATION_MS]
    done = 0
    for (_, params), end in zip(plan, bounds):
        if done:
            lib.wf_host_cpg_set_params(ctypes.byref(to_c(params)))
        steps = end - done
        lib.wf_host_cpg_run(steps, angles[done:].ctypes.data_as(ctypes.POINTER(ctypes.c_float)),
                            phases[done:].ctypes.data_as(ctypes.POINTER(ctypes.c_float)))
        done = end
    angle_error = np.abs(angles.astype(float) - reference)
    aligned = ~np.isnan(reference_phases[:, 0])
    phase_error = np.abs(wrapped(phases[aligned].astype(float) - reference_phases[aligned]))
    top = max(p.frequency_hz for _, p in plan)
    print(f'\nlone C CPG vs CpgIntegrator, 60 s, {CHANGES} changes (up to {top:.2f} Hz): '
          f'max angle error {angle_error.max():.3g} rad, max phase error '
          f'{phase_error.max():.3g} rad ({aligned.sum()} ms compared)')
    assert angle_error.max() <= TOLERANCE_RAD
    assert aligned.sum() > DURATION_MS // 2
    assert phase_error.max() <= TOLERANCE_RAD


def frame(lib: ctypes.CDLL, message: HostMsg) -> bytes:
    """Return the wire frame of ``message`` (the C encoder)."""
    out = ctypes.create_string_buffer(128)
    n = lib.wf_host_encode_stream(ctypes.byref(message), 1, out, len(out))
    assert n > 0
    return out.raw[:n]


def gait_frame(lib: ctypes.CDLL, seq: int, gait_id: int, params: CpgParameters) -> bytes:
    """Return a GAIT frame of ``params``."""
    message = HostMsg(type=GAIT, seq=seq)
    values = (params.frequency_hz, *params.amplitude, *params.offset, params.w12, params.w21,
              params.phi12, params.phi21, params.alpha)
    for i, value in enumerate(values):
        message.f[i] = value
    message.n[0] = gait_id
    return frame(lib, message)


def heartbeat_frame(lib: ctypes.CDLL, seq: int, t_ms: int) -> bytes:
    """Return a host HEARTBEAT of protocol version 2."""
    return frame(lib, HostMsg(type=HEARTBEAT, version_or_code=2, role=0, seq=seq,
                              uptime_or_time_ms=t_ms))


def test_board_in_gait_mode_matches_cpg_integrator_over_60_s(lib: ctypes.CDLL,
                                                             plan_and_reference):
    plan, reference, _ = plan_and_reference
    start = 5  # the board's ms at which the first GAIT arrives: its CPG's time 0
    lib.wf_host_reset()
    lib.wf_host_set_millis(0)
    lib.wf_host_board_init(None)
    changes = {start + t: (gait_id, p) for gait_id, (t, p) in enumerate(plan, start=1)}
    view = GaitView()
    targets = np.empty((DURATION_MS, 2))
    seq = 0
    for now in range(0, start + DURATION_MS + 1):
        data = b''
        if now % 500 == 0:  # the host's heartbeats keep the link up: no coasting
            data += heartbeat_frame(lib, seq, now)
            seq += 1
        if now in changes:
            gait_id, params = changes[now]
            data += gait_frame(lib, seq, gait_id, params)
            seq += 1
        lib.wf_host_board_step(now, data, len(data), None, 0)
        lib.wf_host_board_gait(ctypes.byref(view))
        if now > start:
            targets[now - start - 1] = view.target
    assert view.gait_mode and view.gait_id == len(plan) and view.gap == 0
    assert view.gaits_accepted == len(plan) and view.cpg_steps == DURATION_MS
    expected = np.array([clamp_to_limit(a, (0.0, 0.0), LIMIT)[0] for a in reference])
    error = np.abs(targets - expected)
    print(f'\nboard (GAIT frames, 1 ms polls) vs CpgIntegrator + clamp_to_limit, 60 s: '
          f'max servo target error {error.max():.3g} rad')
    assert error.max() <= TOLERANCE_RAD
