/* SPDX-License-Identifier: Apache-2.0 */
#include "wf/cpg.h"

#include <math.h>
#include <string.h>

/* 2 pi h (h = 1 ms) and 2 pi, each as an unevaluated sum of two binary32 (hi the nearest
 * binary32, lo the rest): together exact to ~1e-15 relative. */
#define TWO_PI_H_HI 0x1.9bc65cp-8f
#define TWO_PI_H_LO -0x1.2e91c8p-33f
#define TWO_PI_HI 0x1.921fb6p+2f
#define TWO_PI_LO -0x1.777a5cp-23f
#define PI_F 0x1.921fb6p+1f /* the binary32 just above pi */
/* A phase this far from [-pi, pi) after one step means a degenerate coupling (|w| ~ 1e4/s
 * and beyond): its value carries nothing worth keeping. GAIT never brings one (|w| <= 100/s,
 * wf_cpg_params_valid); the guard keeps a CPG given unchecked parameters finite. */
#define PHASE_SANE 64.0f

static const float SIXTH_H = WF_CPG_STEP_S / 6.0f;

bool wf_cpg_params_valid(const wf_cpg_params_t *p, float limit)
{
    const float all[] = {p->frequency_hz, p->amplitude[0], p->amplitude[1], p->offset[0],
                         p->offset[1],    p->w12,          p->w21,          p->phi12,
                         p->phi21,        p->alpha};
    for (unsigned i = 0; i < sizeof all / sizeof all[0]; i++) {
        if (!isfinite(all[i])) {
            return false;
        }
    }
    bool ok = p->frequency_hz > 0.0f && p->frequency_hz <= 10.0f && p->alpha > 0.0f &&
              p->alpha <= 200.0f && fabsf(p->w12) <= WF_CPG_MAX_COUPLING &&
              fabsf(p->w21) <= WF_CPG_MAX_COUPLING && fabsf(p->phi12) <= WF_CPG_MAX_PHASE_BIAS &&
              fabsf(p->phi21) <= WF_CPG_MAX_PHASE_BIAS;
    for (unsigned i = 0; i < WF_CPG_OSCILLATORS; i++) {
        ok = ok && p->amplitude[i] >= 0.0f && p->amplitude[i] <= limit &&
             fabsf(p->offset[i]) <= limit;
    }
    return ok;
}

void wf_cpg_set_params(wf_cpg_t *cpg, const wf_cpg_params_t *params)
{
    cpg->params = *params;
    const float v = params->frequency_hz;
    cpg->omega = TWO_PI_HI * v;
    /* v * 2 pi h exactly enough: the product with the hi part and its exact rounding error
     * (one fused multiply-add), plus the product with the lo part. */
    const float p = v * TWO_PI_H_HI;
    cpg->omega_h_hi = p;
    cpg->omega_h_lo = fmaf(v, TWO_PI_H_HI, -p) + v * TWO_PI_H_LO;
}

void wf_cpg_init(wf_cpg_t *cpg, const wf_cpg_params_t *params)
{
    memset(cpg, 0, sizeof *cpg);
    wf_cpg_set_params(cpg, params);
}

void wf_cpg_start(wf_cpg_t *cpg, const wf_cpg_params_t *params, const float offset[2])
{
    wf_cpg_init(cpg, params);
    cpg->b[0] = offset[0];
    cpg->b[1] = offset[1];
}

/* s + e == a + b exactly (Knuth's TwoSum; needs IEEE rounding and no contraction, which ISO
 * C mode gives: GCC's -std=c11 sets -ffp-contract=off). */
static void two_sum(float a, float b, float *s, float *e)
{
    const float sum = a + b;
    const float bb = sum - a;
    *e = (a - (sum - bb)) + (b - bb);
    *s = sum;
}

/* The coupling term of each phase rate, r_j w_ij sin(xi_j - xi_i - phi_ij), for the phase
 * difference delta = xi_2 - xi_1 (eq 1 depends on the phases only through it). */
static void coupling(const wf_cpg_params_t *p, float delta, const float r[2], float c[2])
{
    c[0] = r[1] * p->w12 * sinf(delta - p->phi12);
    c[1] = r[0] * p->w21 * sinf(-delta - p->phi21);
}

/* The rates of r, r', b, b' (eq 1's critically damped laws). */
static void damped(const wf_cpg_params_t *p, const float r[2], const float dr[2],
                   const float b[2], const float db[2], float ddr[2], float ddb[2])
{
    const float alpha = p->alpha;
    const float gain = 0.25f * alpha;
    for (unsigned i = 0; i < 2; i++) {
        ddr[i] = alpha * (gain * (p->amplitude[i] - r[i]) - dr[i]);
        ddb[i] = alpha * (gain * (p->offset[i] - b[i]) - db[i]);
    }
}

static void add_to_phase(wf_cpg_t *cpg, unsigned i, float small)
{
    float s, e;
    two_sum(cpg->phase_hi[i], cpg->omega_h_hi, &s, &e);
    float lo = cpg->phase_lo[i] + (e + small);
    two_sum(s, lo, &cpg->phase_hi[i], &cpg->phase_lo[i]);
    if (!(fabsf(cpg->phase_hi[i]) < PHASE_SANE)) {
        cpg->phase_hi[i] = 0.0f; /* NaN, infinite or absurd: restart the phase */
        cpg->phase_lo[i] = 0.0f;
    }
    while (cpg->phase_hi[i] >= PI_F || cpg->phase_hi[i] < -PI_F) {
        const float turn = cpg->phase_hi[i] >= PI_F ? -1.0f : 1.0f;
        two_sum(cpg->phase_hi[i], turn * TWO_PI_HI, &s, &e);
        lo = cpg->phase_lo[i] + (e + turn * TWO_PI_LO);
        two_sum(s, lo, &cpg->phase_hi[i], &cpg->phase_lo[i]);
    }
}

void wf_cpg_step(wf_cpg_t *cpg)
{
    const wf_cpg_params_t *p = &cpg->params;
    const float delta0 =
        (cpg->phase_hi[1] - cpg->phase_hi[0]) + (cpg->phase_lo[1] - cpg->phase_lo[0]);
    /* Each stage's rates, and their RK4 sums k1 + 2 k2 + 2 k3 + k4 (summed in that order). */
    float c[2], ddr[2], ddb[2];
    float sum_c[2] = {0}, sum_r[2] = {0}, sum_dr[2] = {0}, sum_b[2] = {0}, sum_db[2] = {0};
    float r[2], dr[2], b[2], db[2];
    float delta = delta0;
    memcpy(r, cpg->r, sizeof r);
    memcpy(dr, cpg->dr, sizeof dr);
    memcpy(b, cpg->b, sizeof b);
    memcpy(db, cpg->db, sizeof db);
    static const float weight[3] = {WF_CPG_STEP_S * 0.5f, WF_CPG_STEP_S * 0.5f, WF_CPG_STEP_S};
    static const float multiple[4] = {1.0f, 2.0f, 2.0f, 1.0f};
    for (unsigned k = 0; k < 4; k++) {
        coupling(p, delta, r, c);
        damped(p, r, dr, b, db, ddr, ddb);
        for (unsigned i = 0; i < 2; i++) {
            sum_c[i] += multiple[k] * c[i];
            sum_r[i] += multiple[k] * dr[i];
            sum_dr[i] += multiple[k] * ddr[i];
            sum_b[i] += multiple[k] * db[i];
            sum_db[i] += multiple[k] * ddb[i];
        }
        if (k == 3) {
            break;
        }
        /* The next stage's state: the step's start plus weight * this stage's rates (the
         * free-running 2 pi v of both phases cancels in their difference). */
        const float w = weight[k];
        delta = delta0 + w * (c[1] - c[0]);
        for (unsigned i = 0; i < 2; i++) {
            const float rate_r = dr[i], rate_b = db[i];
            r[i] = cpg->r[i] + w * rate_r;
            dr[i] = cpg->dr[i] + w * ddr[i];
            b[i] = cpg->b[i] + w * rate_b;
            db[i] = cpg->db[i] + w * ddb[i];
        }
    }
    for (unsigned i = 0; i < 2; i++) {
        add_to_phase(cpg, i, cpg->omega_h_lo + SIXTH_H * sum_c[i]);
        cpg->r[i] += SIXTH_H * sum_r[i];
        cpg->dr[i] += SIXTH_H * sum_dr[i];
        cpg->b[i] += SIXTH_H * sum_b[i];
        cpg->db[i] += SIXTH_H * sum_db[i];
    }
    cpg->steps++;
}

float wf_cpg_phase(const wf_cpg_t *cpg, unsigned i)
{
    return i < WF_CPG_OSCILLATORS ? cpg->phase_hi[i] + cpg->phase_lo[i] : 0.0f;
}

void wf_cpg_output(const wf_cpg_t *cpg, float angle[2], float rate[2])
{
    float c[2];
    if (rate != NULL) {
        const float delta =
            (cpg->phase_hi[1] - cpg->phase_hi[0]) + (cpg->phase_lo[1] - cpg->phase_lo[0]);
        coupling(&cpg->params, delta, cpg->r, c);
    }
    for (unsigned i = 0; i < 2; i++) {
        const float xi = cpg->phase_hi[i] + cpg->phase_lo[i];
        const float cos_xi = cosf(xi);
        angle[i] = cpg->r[i] * cos_xi + cpg->b[i];
        if (rate != NULL) {
            rate[i] = cpg->dr[i] * cos_xi - cpg->r[i] * (cpg->omega + c[i]) * sinf(xi) +
                      cpg->db[i];
        }
    }
}

bool wf_cpg_clamp(float angle[2], float rate[2], float limit)
{
    bool clipped = false;
    for (unsigned i = 0; i < 2; i++) {
        if (!(fabsf(angle[i]) <= limit)) {
            angle[i] = fminf(limit, fmaxf(-limit, angle[i]));
            if (rate != NULL) {
                rate[i] = 0.0f;
            }
            clipped = true;
        }
    }
    return clipped;
}
