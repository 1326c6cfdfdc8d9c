/* SPDX-License-Identifier: Apache-2.0 */
/*
 * The fish's central pattern generator on the board: eq 1 of the paper (two coupled phase
 * oscillators) with the rules of wirefish_cpg.oscillator.CpgIntegrator, in binary32.
 *
 *   d xi_i / dt = 2 pi v + r_j w_ij sin(xi_j - xi_i - phi_ij)          (j the other one)
 *   r_i''       = alpha (alpha / 4 (R_i - r_i) - r_i')                  (critically damped)
 *   b_i''       = alpha (alpha / 4 (B_i - b_i) - b_i')                  (offset: same law)
 *   Theta_i     = r_i cos(xi_i) + b_i
 *
 * Fixed-step classical RK4, step WF_CPG_STEP_MS. New parameters only swap the targets (R, B,
 * v, w, phi, alpha): the state persists, so the output and its rate never step. The state
 * starts at rest (every phase, amplitude, offset and rate 0), or (wf_cpg_start) at rest with
 * the offsets b_i at given angles.
 *
 * Precision: the phase is kept as an unevaluated sum hi + lo of two binary32, hi wrapped to
 * [-pi, pi). The free-running part of each step, 2 pi v h, is added with an error-free sum
 * (its rounding goes into lo instead of being lost), so over a minute of up to 10 Hz (3770 rad
 * of phase in the float64 reference) the phase stays within a few 1e-6 rad of the float64
 * integration. A plain binary32 phase loses up to half an ulp per step, the same way every
 * step at a fixed frequency: 3.4e-4 rad of output angle in test_fw_cpg_parity's minute.
 */
#ifndef WF_CPG_H
#define WF_CPG_H

#include <stdbool.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* 1 ms (1 kHz). At least 500 Hz is asked of the board; 1 kHz is CpgIntegrator's default step,
 * so the host's CPG node and the board integrate exactly the same steps from the same start
 * (their outputs then differ by binary32 rounding only, not by discretisation), and 1 ms is
 * the tick of wf_hal_millis, so one step per millisecond of the board's clock needs no
 * fractional bookkeeping. A step costs 1691 instructions on the Cortex-M4 build (make
 * cpg-arm-count), some 2000 to 2500 cycles: 12 to 15 us of each 1 ms at 168 MHz. */
#define WF_CPG_STEP_MS 1u
#define WF_CPG_STEP_S 1e-3f

enum { WF_CPG_OSCILLATORS = 2 };

/* The parameters of eq 1 for the fish's two oscillators, as GAIT carries them (SI, rad):
 * the shared intrinsic frequency v, the amplitude targets R_i and offset targets B_i, the
 * coupling weights w12 (of oscillator 2 on 1) and w21 (1/s), the phase biases phi12, phi21,
 * and the convergence gain alpha (1/s). */
typedef struct {
    float frequency_hz;
    float amplitude[WF_CPG_OSCILLATORS];
    float offset[WF_CPG_OSCILLATORS];
    float w12, w21;
    float phi12, phi21;
    float alpha;
} wf_cpg_params_t;

typedef struct {
    float phase_hi[WF_CPG_OSCILLATORS]; /* xi_i = phase_hi + phase_lo, hi in [-pi, pi) */
    float phase_lo[WF_CPG_OSCILLATORS];
    float r[WF_CPG_OSCILLATORS], dr[WF_CPG_OSCILLATORS];
    float b[WF_CPG_OSCILLATORS], db[WF_CPG_OSCILLATORS];
    wf_cpg_params_t params;
    float omega;                   /* 2 pi v (rad/s) */
    float omega_h_hi, omega_h_lo;  /* 2 pi v h as an unevaluated sum (rad per step) */
    uint32_t steps;                /* steps taken since wf_cpg_init or wf_cpg_start */
} wf_cpg_t;

/* The couplings GAIT accepts. |w_ij| <= 100/s: with r_j <= pi/2 a coupling term is at most
 * 157 rad/s, so a phase moves at most 0.22 rad per 1 ms step (with 2 pi 10 Hz) and the phase
 * difference's stiffness r (|w12| + |w21|) <= 314/s gives h lambda <= 0.31, well inside RK4's
 * stability (2.78) and its accurate range; the paper's Table 1 has |w| < 1 and the CPG node
 * allows 10. |phi_ij| <= 2 pi: every bias has a representative there; beyond it is a unit
 * mistake (degrees), not a gait. WF_CPG_MAX_PHASE_BIAS is the largest binary32 not above 2 pi,
 * so a binary32 bias is refused exactly when wirefish_bridge's Gait.problem refuses it (its
 * 2 pi is a double). */
#define WF_CPG_MAX_COUPLING 100.0f
#define WF_CPG_MAX_PHASE_BIAS 0x1.921fb4p+2f

/* True when params can drive the board: every value finite, 0 < v <= 10 Hz,
 * 0 <= R_i <= limit, |B_i| <= limit, |w12|, |w21| <= WF_CPG_MAX_COUPLING (1/s),
 * |phi12|, |phi21| <= WF_CPG_MAX_PHASE_BIAS (rad), 0 < alpha <= 200 (1/s) (the GAIT rules of
 * PROTOCOL.md). */
bool wf_cpg_params_valid(const wf_cpg_params_t *params, float servo_limit_rad);

/* At rest (all state 0) with params' targets. */
void wf_cpg_init(wf_cpg_t *cpg, const wf_cpg_params_t *params);

/* At rest but for the offsets: b_i = offset[i] (rad), every phase, amplitude and rate 0, so
 * the output starts at Theta_i = offset[i] with rate 0 and converges to the targets through
 * alpha. Gait mode starts here from the angles stream mode held: no step at the switch. */
void wf_cpg_start(wf_cpg_t *cpg, const wf_cpg_params_t *params,
                  const float offset[WF_CPG_OSCILLATORS]);

/* Swaps the targets; the state persists (CpgIntegrator.set_parameters). */
void wf_cpg_set_params(wf_cpg_t *cpg, const wf_cpg_params_t *params);

/* One RK4 step of WF_CPG_STEP_S. */
void wf_cpg_step(wf_cpg_t *cpg);

/* Theta_i (rad) of the state now, and (rate not NULL) its exact time derivative (rad/s). */
void wf_cpg_output(const wf_cpg_t *cpg, float angle[WF_CPG_OSCILLATORS],
                   float rate[WF_CPG_OSCILLATORS]);

/* Oscillator i's phase xi_i, wrapped to [-pi, pi) (rad). */
float wf_cpg_phase(const wf_cpg_t *cpg, unsigned i);

/* wirefish_cpg.servo_limit.clamp_to_limit: clips each angle to [-limit, limit] and, when rate
 * is not NULL, zeroes the rate of a clipped servo (it holds still at the limit). Returns true
 * when any angle was clipped. */
bool wf_cpg_clamp(float angle[WF_CPG_OSCILLATORS], float rate[WF_CPG_OSCILLATORS],
                  float limit_rad);

#ifdef __cplusplus
}
#endif

#endif /* WF_CPG_H */
