/* The FMI 2.0 runtime of a suspopt design (model exchange and co-simulation).
 *
 * Written by suspopt (suspopt/fmu/runtime.c); the design itself is in model.c / model.h,
 * generated from its element network (suspopt/network.py): DOFs with masses, element groups
 * along deformations  d = D_q q + D_u u, forces  F = k d + c d' (+ a law's part), and
 *
 *     M q'' = G F,   G = -D_q^T (masked where a one-way seat does not push the body).
 *
 * Co-simulation steps with suspopt's own classical RK4 at the config's dt (the stages scaled
 * by their step as suspopt.integrator.rk4 does; a step that holds a road edge split at it,
 * with the edge's exact impulse), the semi-active controller sampled every dT with its
 * zero-order hold and its actuator's first-order lag per step. Model exchange gives the same
 * right-hand side to the importer's solver, with the controller's samples, the lag's steps
 * and the road's edges as time events.
 *
 * The entries (every number of the model) follow the tunable parameters as measured at
 * export (suspopt/fmu/params.py): e = e0 * prod (p/p0)^d, or e = alpha * p for a parameter
 * that is 0 in the design. Derived at run time: M^-1, the static load of each tyre (the
 * vehicle's linear statics K q0 = -M g), the actuator's decay exp(-dt/tau).
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fmi2Functions.h"
#include "model.h"

#define N2 (2 * SU_N)
#define NC SU_NU /* corners: one road input each */
#define SU_LIMIT 1.0e6 /* |state| above this is divergence (suspopt.integrator.DIVERGENCE_LIMIT) */

enum { PH_INSTANTIATED, PH_INIT, PH_STEP, PH_EVENT, PH_CONTINUOUS, PH_TERMINATED, PH_ERROR };

typedef struct {
    const fmi2CallbackFunctions *cb;
    char name[128];
    int cs, logging, phase, dirty, valid, sampled, diverged;
    long k;          /* co-simulation: the current step, t = k dt */
    double time;
    double par[SU_NPAR1];
    double E[SU_NE1];
    double inv_m[SU_N1], static_f[SU_R1], c_now[SU_R1], decay;
    double y[N2 + 1], ys[N2 + 1], s1[N2 + 1], s2[N2 + 1], s3[N2 + 1], s4[N2 + 1];
    double k1[N2 + 1], k2[N2 + 1], k3[N2 + 1], k4[N2 + 1];
    double a[SU_N1], raw[SU_N1];
    double d[SU_R1], dv[SU_R1], fel[SU_R1], fvis[SU_R1], ftot[SU_R1];
    double Q[SU_NQ1], out[SU_NOUT1];
    double u_set[2 * NC + 1], du_set[2 * NC + 1], d2u_set[2 * NC + 1], t_set, uz[2 * NC + 1];
    /* the controller */
    double cmd[NC + 1], cond[NC + 1], thr[NC + 1], stiff[NC + 1], pulled[NC + 1];
    double *history; long hist_n, hist_cap; double next_fit, next_due;
    /* model exchange */
    long next_control; int next_edge;
} Inst;

static void su_log(Inst *m, fmi2Status status, const char *category, const char *fmt, ...)
{
    char text[512];
    va_list args;
    if (m == NULL || m->cb == NULL || m->cb->logger == NULL) return;
    if (!m->logging && status == fmi2OK) return;
    va_start(args, fmt);
    vsnprintf(text, sizeof text, fmt, args);
    va_end(args);
    m->cb->logger(m->cb->componentEnvironment, m->name, status, category, "%s", text);
}

static fmi2Status su_fail(Inst *m, const char *fmt, const char *what)
{
    su_log(m, fmi2Error, "logStatusError", fmt, what);
    return fmi2Error;
}

double su_where(double c, double a, double b) { return c != 0.0 ? a : b; }

double su_clip(double x, double lo, double hi)
{
    /* np.clip: maximum then minimum, NaN kept */
    double v = x < lo ? lo : x;
    return v > hi ? hi : v;
}

/* ---------------------------------------------------------------- entries and statics */

static double su_power(double r, int d)
{
    switch (d) {
    case 1: return r;
    case 2: return r * r;
    case -1: return 1.0 / r;
    case -2: return 1.0 / (r * r);
    default: return pow(r, (double)d);
    }
}

static void su_statics(Inst *m)
{
    /* the vehicle's linear statics K q0 = -M g (translations), K = D^T diag(k) D over its
       own groups; each tyre's static load -k (D q0) (suspopt.vehicle._static_tyre_load) */
    double K[SU_NV1 * SU_NV1], f[SU_NV1], q0[SU_NV1];
    int i, j, z, w, r, p;
    const int nv = SU_NV;
    memset(K, 0, sizeof K);
    for (z = 0; z < SU_ND; z++) {
        r = su_dq_row[z];
        if (r >= SU_VEHICLE_ROWS) continue;
        for (w = 0; w < SU_ND; w++) {
            if (su_dq_row[w] != r) continue;
            K[su_dq_col[z] * nv + su_dq_col[w]] +=
                m->E[E_DQ + z] * m->E[E_K + r] * m->E[E_DQ + w];
        }
    }
    for (i = 0; i < nv; i++) f[i] = su_weighted[i] ? -m->E[E_MASS + i] * m->E[E_GRAVITY] : 0.0;
    for (i = 0; i < nv; i++) { /* Gaussian elimination, partial pivoting (LAPACK's gesv) */
        p = i;
        for (j = i + 1; j < nv; j++)
            if (fabs(K[j * nv + i]) > fabs(K[p * nv + i])) p = j;
        if (p != i) {
            for (j = 0; j < nv; j++) {
                double t = K[i * nv + j]; K[i * nv + j] = K[p * nv + j]; K[p * nv + j] = t;
            }
            { double t = f[i]; f[i] = f[p]; f[p] = t; }
        }
        for (j = i + 1; j < nv; j++) {
            double l = K[j * nv + i] / K[i * nv + i];
            int c;
            for (c = i; c < nv; c++) K[j * nv + c] -= l * K[i * nv + c];
            f[j] -= l * f[i];
        }
    }
    for (i = nv - 1; i >= 0; i--) {
        double s = f[i];
        for (j = i + 1; j < nv; j++) s -= K[i * nv + j] * q0[j];
        q0[i] = s / K[i * nv + i];
    }
    for (r = 0; r < SU_R; r++) m->static_f[r] = 0.0;
    for (i = 0; i < SU_NTYRE; i++) {
        double s = 0.0;
        r = su_tyre_rows[i];
        for (z = 0; z < SU_ND; z++)
            if (su_dq_row[z] == r) s += m->E[E_DQ + z] * q0[su_dq_col[z]];
        m->static_f[r] = -m->E[E_K + r] * s;
    }
}

static void su_entries(Inst *m)
{
    int g, b, i, r;
    memcpy(m->E, su_e0, sizeof(double) * SU_NE);
    for (g = 0; g < SU_NRANGE; g++) {
        double factor = 1.0;
        int zero = su_range_zero[g];
        for (b = su_range_bind[g]; b < su_range_bind[g + 1]; b++) {
            int p = su_bind_par[b];
            factor *= su_power(m->par[p] / su_par0[p], su_bind_deg[b]);
        }
        for (i = 0; i < su_range_count[g]; i++) {
            int e = su_range_start[g] + i;
            m->E[e] = zero >= 0 ? su_alpha[su_range_alpha[g] + i] * m->par[zero] * factor
                                : su_e0[e] * factor;
        }
    }
    for (i = 0; i < SU_N; i++) m->inv_m[i] = 1.0 / m->E[E_MASS + i];
    for (r = 0; r < SU_R; r++) {
        int controlled = 0;
        for (i = 0; i < SU_NDAMPERS; i++) controlled |= su_damper_rows[i] == r;
        if (!controlled) m->c_now[r] = m->E[E_C + r];
    }
    su_statics(m);
#if SU_CONTROLLED
    {
        double tau = m->E[E_ACTUATOR_LAG];
        m->decay = tau > 0 ? exp(-m->E[E_DT] / tau) : 0.0;
    }
#endif
    m->dirty = 0;
    m->valid = 0;
}

/* ---------------------------------------------------------------- the network's forces */

static double su_law_extra(int code, double d, double f, const double *p, double cap)
{
    /* the non-linear part F_x of suspopt.integrator.compiled.LAWS, given F = k d + c d' */
    double w, x;
    if (code == 0) return ((p[2] * d + p[1]) * d + p[0]) * d;   /* poly3: Duffing, Taylor */
    if (code == 1) return (f > cap ? cap : f) - f;             /* cap: a tyre lifts off */
    w = p[3] + d;
    if (code == 2) x = (p[0] + p[1] / sqrt(p[2] - w * w)) * w; /* link: NSS2-NSS4 */
    else x = (p[1] / sqrt(w * w + p[2]) + p[0]) * w;           /* carrella: NSS1 */
    return x + p[4];
}

/* G F into m->raw (not yet times M^-1) at the state y with the road uz = [z; zdot] */
static void su_forces(Inst *m, const double *y, const double *uz)
{
    int z, r, x;
    for (r = 0; r < SU_R; r++) m->d[r] = m->dv[r] = 0.0;
    for (z = 0; z < SU_ND; z++) {
        r = su_dq_row[z];
        m->d[r] += m->E[E_DQ + z] * y[su_dq_col[z]];
        m->dv[r] += m->E[E_DQ + z] * y[SU_N + su_dq_col[z]];
    }
    for (z = 0; z < SU_NDU; z++) {
        r = su_du_row[z];
        m->d[r] += m->E[E_DU + z] * uz[su_du_col[z]];
        m->dv[r] += m->E[E_DU + z] * uz[NC + su_du_col[z]];
    }
    for (r = 0; r < SU_R; r++) {
        m->fel[r] = m->E[E_K + r] * m->d[r];
        m->fvis[r] = m->c_now[r] * m->dv[r];
        m->ftot[r] = m->fel[r] + m->fvis[r];
    }
    for (x = 0; x < SU_NX; x++) {
        r = su_law_row[x];
        {
            double extra = su_law_extra(su_law_code[x], m->d[r], m->ftot[r], &m->E[E_LAW + 5 * x],
                                        m->static_f[r]);
            m->fel[r] += extra;
            m->ftot[r] += extra;
        }
    }
    for (r = 0; r < SU_N; r++) m->raw[r] = 0.0;
    for (z = 0; z < SU_ND; z++)
        if (su_dq_react[z]) m->raw[su_dq_col[z]] -= m->E[E_DQ + z] * m->ftot[su_dq_row[z]];
}

/* out = [h v ; h a] at the state y (h = 0: out holds the accelerations only, unscaled) */
static void su_slope(Inst *m, const double *y, const double *uz, double h, double *out)
{
    int i;
    su_forces(m, y, uz);
    for (i = 0; i < SU_N; i++) {
        if (h == 0.0) {
            out[SU_N + i] = m->raw[i] * m->inv_m[i];
            out[i] = y[SU_N + i];
        } else {
            out[SU_N + i] = m->raw[i] * (m->inv_m[i] * h);
            out[i] = y[SU_N + i] * h;
        }
    }
}

/* ---------------------------------------------------------------- the road */

/* the road at half step j (co-simulation) into m->uz, or from the inputs at time t */
static const double *su_road_half(Inst *m, long j, double t)
{
#if SU_EMBEDDED
    (void)t;
    return &m->E[E_ROAD_TABLE + j * 2 * NC];
#else
    int i;
    (void)j;
    double tau = t - m->t_set;
    /* the inputs' Taylor polynomial from their last values and the derivatives the master
       gave (first and second order; none: held) */
    for (i = 0; i < 2 * NC; i++)
        m->uz[i] = m->u_set[i] + tau * (m->du_set[i] + 0.5 * tau * m->d2u_set[i]);
    for (i = 0; i < NC; i++) /* no rate input (the tyre does not damp): the height's slope */
        if (!su_rate_input[i]) m->uz[NC + i] = m->du_set[i] + tau * m->d2u_set[i];
    return m->uz;
#endif
}

#if SU_EMBEDDED
static void su_hermite(double t, double a, double b, const double *va, const double *vb,
                       double *out)
{
    double h = b - a, s, s2, s3;
    int i;
    if (h <= 0.0) {
        memcpy(out, va, sizeof(double) * 2 * NC);
        return;
    }
    s = (t - a) / h;
    s2 = s * s;
    s3 = s2 * s;
    for (i = 0; i < NC; i++) {
        double z0 = va[i], z1 = vb[i], r0 = va[NC + i] * h, r1 = vb[NC + i] * h;
        out[i] = (2 * s3 - 3 * s2 + 1) * z0 + (s3 - 2 * s2 + s) * r0 + (3 * s2 - 2 * s3) * z1
                 + (s3 - s2) * r1;
        out[NC + i] = ((6 * s2 - 6 * s) * z0 + (3 * s2 - 4 * s + 1) * r0 + (6 * s - 6 * s2) * z1
                       + (3 * s2 - 2 * s) * r1) / h;
    }
}
#endif

/* the road at any time t (model exchange): cubic Hermite between the half-step grid's knots
   and the edges' one-sided limits; from the inputs without an embedded road */
static const double *su_road_at(Inst *m, double t)
{
#if SU_EMBEDDED
    const double hdt = 0.5 * m->E[E_DT];
    long j = (long)floor(t / hdt);
    double a, b;
    const double *va, *vb;
    int e;
    if (t >= SU_ROAD_END) return &m->E[E_ROAD_TABLE + 2 * SU_STEPS * 2 * NC];
    if (j < 0) j = 0;
    if (j >= 2 * SU_STEPS) j = 2 * SU_STEPS - 1;
    a = j * hdt;
    b = (j + 1) * hdt;
    va = &m->E[E_ROAD_TABLE + j * 2 * NC];
    vb = &m->E[E_ROAD_TABLE + (j + 1) * 2 * NC];
    for (e = 0; e < SU_NEDGES; e++) {
        double te = m->E[E_EDGE_TIME + e];
        if (te > a && te <= t) { a = te; va = &m->E[E_EDGE_RIGHT + e * 2 * NC]; }
        if (te > t && te <= b) { b = te; vb = &m->E[E_EDGE_LEFT + e * 2 * NC]; break; }
    }
    if (t <= a) return va;
    su_hermite(t, a, b, va, vb, m->uz);
    return m->uz;
#else
    (void)t;
    return m->u_set;
#endif
}

#if SU_EMBEDDED
static void su_impulse(Inst *m, int e)
{
    /* the velocity jump M^-1 G (c D_u du) of the road's jump du at edge e; a tyre that
       cannot pull takes no pulling impulse (suspopt.integrator.rk4._Splitter.impulse) */
    double force[SU_R1], jump[SU_N1];
    int z, r, i;
    for (r = 0; r < SU_R; r++) force[r] = 0.0;
    for (z = 0; z < SU_NDU; z++)
        force[su_du_row[z]] += m->E[E_DU + z] * m->E[E_EDGE_JUMP + e * NC + su_du_col[z]];
    for (r = 0; r < SU_R; r++) {
        force[r] = m->c_now[r] * force[r];
        if (su_no_pull[r] && force[r] > 0.0) force[r] = 0.0;
    }
    for (i = 0; i < SU_N; i++) jump[i] = 0.0;
    for (z = 0; z < SU_ND; z++)
        if (su_dq_react[z]) jump[su_dq_col[z]] -= m->E[E_DQ + z] * force[su_dq_row[z]];
    for (i = 0; i < SU_N; i++) m->y[SU_N + i] += jump[i] * m->inv_m[i];
}
#endif

/* ---------------------------------------------------------------- the controller */

#if SU_CONTROLLED
static int su_compare(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    if (isnan(x)) return isnan(y) ? 0 : 1;
    if (isnan(y)) return -1;
    return (x > y) - (x < y);
}

static double su_quantile(Inst *m, int c)
{
    /* the empirical quantile (numpy's linear method) or the normal fit mu + sigma z of the
       history of corner c's condition (suspopt.control.stats.distribution_quantile) */
    long n = m->hist_n, i;
    double level = m->E[E_LEVEL + c];
    if (SU_DISTRIBUTION == 1) {
        double mean = 0.0, var = 0.0;
        for (i = 0; i < n; i++) mean += m->history[i * NC + c];
        mean /= (double)n;
        for (i = 0; i < n; i++) {
            double dx = m->history[i * NC + c] - mean;
            var += dx * dx;
        }
        return mean + sqrt(var / (double)n) * m->E[E_NORMAL_Z + c];
    } else {
        double *x = (double *)malloc(sizeof(double) * (size_t)n), pos, lo_v, hi_v, r;
        long lo;
        for (i = 0; i < n; i++) x[i] = m->history[i * NC + c];
        qsort(x, (size_t)n, sizeof(double), su_compare);
        pos = level * (double)(n - 1);
        lo = (long)floor(pos);
        lo_v = x[lo];
        hi_v = lo + 1 < n ? x[lo + 1] : lo_v;
        r = lo_v + (hi_v - lo_v) * (pos - (double)lo);
        free(x);
        return r;
    }
}

static void su_refit(Inst *m, double t, const double *x)
{
    /* suspopt.control.controller.SemiActiveController._refit, for one design */
    const double hs = 0.5 * m->E[E_DT];
    int c;
    if (m->hist_n == m->hist_cap) {
        long cap = m->hist_cap ? 2 * m->hist_cap : 1024;
        double *grown = (double *)realloc(m->history, sizeof(double) * (size_t)(cap * NC));
        if (grown == NULL) return;
        m->history = grown;
        m->hist_cap = cap;
    }
    for (c = 0; c < NC; c++) m->history[m->hist_n * NC + c] = x[c];
    m->hist_n++;
    if (t + hs < m->next_due) return;
    if (t + hs >= m->next_fit) {
        double period = m->E[E_REFIT_FACTOR] * m->E[E_LEARN_TIME];
        double late = t + hs - m->next_fit, following;
        for (c = 0; c < NC; c++) m->thr[c] = su_quantile(m, c);
        following = m->next_fit + period * (floor(late / period) + 1.0);
        m->next_fit = isfinite(following) ? following : t + hs;
    }
    m->next_due = m->next_fit;
}
#endif

/* the controller at step k (suspopt.integrator.rk4._ControllerHold.control): its sample when
   one is due (the law's condition, the threshold, the command held), then the lag */
static void su_control(Inst *m, long k, const double *uz)
{
#if SU_CONTROLLED
    int c;
    if (k % SU_EVERY == 0) {
        double rates[3 * NC], za[NC], x[NC];
        int z;
        for (z = 0; z < 3 * NC; z++) rates[z] = 0.0;
        for (z = 0; z < SU_NRATE; z++)
            rates[su_rate_row[z]] += m->E[E_RATES + z] * m->y[SU_N + su_rate_col[z]];
        for (c = 0; c < NC; c++) za[c] = 0.0;
        if (SU_NEEDS_ACC) {
            su_slope(m, m->y, uz, 0.0, m->k1);
            for (z = 0; z < SU_NRATE; z++)
                if (su_rate_row[z] >= NC && su_rate_row[z] < 2 * NC)
                    za[su_rate_row[z] - NC] += m->E[E_RATES + z] * m->k1[SU_N + su_rate_col[z]];
        }
        for (c = 0; c < NC; c++) {
            const double *p = &m->E[E_LAW_PARAMETERS];
            x[c] = su_laws[c] < 0 ? 0.0
                                  : su_condition(su_laws[c], rates[c], rates[NC + c],
                                                 rates[2 * NC + c], za[c], p[c], p[NC + c],
                                                 p[2 * NC + c]);
        }
#if SU_ADAPTIVE
        su_refit(m, (double)k * m->E[E_DT], x);
#endif
        for (c = 0; c < NC; c++) {
            const double *p = &m->E[E_LAW_PARAMETERS];
            double lo = m->E[E_C_MIN + c], hi = m->E[E_C_MAX + c], stiff_c = hi;
            int stiff = su_below[c] ? x[c] < m->thr[c] : x[c] > m->thr[c];
            if (su_laws[c] >= 0 && su_continuous(su_laws[c]))
                stiff_c = su_stiff(su_laws[c], lo, hi, rates[c], rates[NC + c], x[c], p[c],
                                   p[NC + c], p[2 * NC + c]);
            m->cmd[c] = stiff ? stiff_c : lo;
            m->cond[c] = x[c];
            m->stiff[c] = stiff;
            if (SU_LAGGED) m->pulled[c] = m->cmd[c] * (1.0 - m->decay);
            else m->c_now[su_damper_rows[c]] = m->cmd[c];
        }
    }
    if (SU_LAGGED)
        for (c = 0; c < NC; c++) {
            int r = su_damper_rows[c];
            m->c_now[r] = m->c_now[r] * m->decay;
            m->c_now[r] = m->c_now[r] + m->pulled[c];
        }
#else
    (void)m; (void)k; (void)uz;
#endif
}

static void su_controller_start(Inst *m)
{
#if SU_CONTROLLED
    int c;
    for (c = 0; c < NC; c++) {
        m->cmd[c] = m->E[E_C_MIN + c];
        m->c_now[su_damper_rows[c]] = m->cmd[c];
        m->cond[c] = 0.0;
        m->stiff[c] = 0.0;
        m->thr[c] = m->E[E_THRESHOLD + c];
        m->pulled[c] = 0.0;
    }
    m->hist_n = 0;
#if SU_ADAPTIVE
    m->next_fit = m->E[E_LEARN_TIME];
    m->next_due = m->next_fit;
#endif
#else
    (void)m;
#endif
}

/* ---------------------------------------------------------------- co-simulation steps */

static void su_regular_step(Inst *m, const double *u1, const double *u2)
{
    /* suspopt.integrator.rk4._RK4.rest: s1 = dt/2 k1 (k1 in m->a), s2 = dt/2 k2, s3 = dt k3,
       s4 = dt/6 k4, y += (s1 + 2 s2 + s3)/3 + s4 */
    const double dt = m->E[E_DT], half = 0.5 * dt, third = 1.0 / 3.0;
    int i;
    for (i = 0; i < SU_N; i++) {
        m->s1[SU_N + i] = m->a[i] * half;
        m->s1[i] = m->y[SU_N + i] * half;
    }
    for (i = 0; i < N2; i++) m->ys[i] = m->y[i] + m->s1[i];
    su_slope(m, m->ys, u1, half, m->s2);
    for (i = 0; i < N2; i++) m->ys[i] = m->y[i] + m->s2[i];
    su_slope(m, m->ys, u1, dt, m->s3);
    for (i = 0; i < N2; i++) m->ys[i] = m->y[i] + m->s3[i];
    su_slope(m, m->ys, u2, dt / 6.0, m->s4);
    for (i = 0; i < N2; i++) m->y[i] += (((m->s1[i] + m->s3[i]) + m->s2[i] * 2.0) * third) + m->s4[i];
}

#if SU_EMBEDDED
static void su_split_step(Inst *m, int s, const double *u0)
{
    /* suspopt.integrator.rk4._Splitter.step: RK4 sub-steps between the step's edges, each
       edge's impulse at its instant */
    int j, i;
    for (j = su_split_first[s]; j < su_split_first[s + 1]; j++) {
        const double h = m->E[E_SPLIT_H + j];
        const double *right = j == su_split_first[s] ? u0 : &m->E[E_SPLIT_RIGHT + j * 2 * NC];
        const double *mid = &m->E[E_SPLIT_MIDDLE + j * 2 * NC];
        const double *left = &m->E[E_SPLIT_LEFT + j * 2 * NC];
        su_slope(m, m->y, right, 0.0, m->k1);
        for (i = 0; i < N2; i++) m->ys[i] = m->y[i] + 0.5 * h * m->k1[i];
        su_slope(m, m->ys, mid, 0.0, m->k2);
        for (i = 0; i < N2; i++) m->ys[i] = m->y[i] + 0.5 * h * m->k2[i];
        su_slope(m, m->ys, mid, 0.0, m->k3);
        for (i = 0; i < N2; i++) m->ys[i] = m->y[i] + h * m->k3[i];
        su_slope(m, m->ys, left, 0.0, m->k4);
        for (i = 0; i < N2; i++)
            m->y[i] += h / 6.0 * (m->k1[i] + 2.0 * (m->k2[i] + m->k3[i]) + m->k4[i]);
        if (su_split_kick[j] >= 0) su_impulse(m, su_split_kick[j]);
    }
}
#endif

static int su_split_of(long k)
{
#if SU_EMBEDDED
    int s;
    for (s = 0; s < SU_NSPLIT; s++)
        if (su_split_steps[s] == k) return s;
#else
    (void)k;
#endif
    return -1;
}

/* the sample at the current step: the controller's (once), the accelerations f(y_k) */
static void su_sample(Inst *m)
{
    const double *u0 = su_road_half(m, 2 * m->k, m->time);
    if (!m->sampled) {
        su_control(m, m->k, u0);
        m->sampled = 1;
    }
    su_slope(m, m->y, u0, 0.0, m->k1);
    memcpy(m->a, &m->k1[SU_N], sizeof(double) * SU_N);
}

static int su_cs_step(Inst *m)
{
    const double dt = m->E[E_DT];
    int s, i;
    su_sample(m);
    s = su_split_of(m->k);
    if (s < 0) {
        double u1[2 * NC + 1], u2[2 * NC + 1];
        memcpy(u1, su_road_half(m, 2 * m->k + 1, (m->k + 0.5) * dt), sizeof(double) * 2 * NC);
        memcpy(u2, su_road_half(m, 2 * m->k + 2, (m->k + 1) * dt), sizeof(double) * 2 * NC);
        su_regular_step(m, u1, u2);
    }
#if SU_EMBEDDED
    else su_split_step(m, s, su_road_half(m, 2 * m->k, m->time));
#endif
    m->k++;
    m->time = (double)m->k * dt;
    m->sampled = 0;
    m->valid = 0;
    for (i = 0; i < N2; i++)
        if (!(fabs(m->y[i]) < SU_LIMIT)) return 0;
    return 1;
}

/* ---------------------------------------------------------------- outputs */

static double su_record(Inst *m, int kind, int c)
{
#if SU_CONTROLLED
    if (su_laws[c] < 0) return NAN; /* a passive corner has no records */
    if (kind == 1) return m->cond[c];
    if (kind == 2) return m->thr[c];
    {
        double lo = m->E[E_C_MIN + c], hi = m->E[E_C_MAX + c];
        if (SU_STIFF_RECORDS && !(hi > lo)) return m->stiff[c];
        return (m->cmd[c] - lo) / (hi > lo ? hi - lo : 1.0);
    }
#else
    (void)m; (void)kind; (void)c;
    return NAN;
#endif
}

static void su_outputs(Inst *m)
{
    const double *uz;
    double *Q = m->Q;
    int i, r;
    if (m->dirty) su_entries(m);
    if (m->valid) return;
    if (m->cs) {
        su_sample(m);
        uz = su_road_half(m, 2 * m->k, m->time);
    } else {
        uz = su_road_at(m, m->time);
        su_slope(m, m->y, uz, 0.0, m->k1);
        memcpy(m->a, &m->k1[SU_N], sizeof(double) * SU_N);
    }
    su_forces(m, m->y, uz); /* (the forces of the sample's state, for the element signals) */
    for (i = 0; i < SU_N; i++) {
        Q[Q_Q + i] = m->y[i];
        Q[Q_V + i] = m->y[SU_N + i];
        Q[Q_A + i] = m->a[i];
    }
    for (i = 0; i < NC; i++) {
        Q[Q_U + i] = uz[i];
        Q[Q_UD + i] = uz[NC + i];
    }
    for (r = 0; r < SU_R; r++) {
        Q[Q_D + r] = m->d[r];
        Q[Q_DV + r] = m->dv[r];
        Q[Q_F_ELASTIC + r] = m->fel[r];
        Q[Q_F_VISCOUS + r] = m->fvis[r];
        Q[Q_F_TOTAL + r] = m->ftot[r];
        Q[Q_C_NOW + r] = m->c_now[r];
        Q[Q_STATIC + r] = m->static_f[r];
    }
    Q[Q_BASE] = Q[Q_BASE + 1] = Q[Q_BASE + 2] = 0.0;
    for (i = 0; i < SU_NV; i++) {
        double p = m->E[E_SEAT_POINT + i];
        Q[Q_BASE] += p * m->y[i];
        Q[Q_BASE + 1] += p * m->y[SU_N + i];
        Q[Q_BASE + 2] += p * m->a[i];
    }
    Q[Q_MECH] = SU_MECH_ROW >= 0 ? m->E[E_MECH_REST] + m->d[SU_MECH_ROW > 0 ? SU_MECH_ROW : 0] : 0.0;
    for (i = 0; i < SU_NOUT; i++) {
        int a = su_out_i[i], b = su_out_j[i];
        switch (su_out_kind[i]) {
        case 0: m->out[i] = Q[a]; break;
        case 1: m->out[i] = Q[a] - Q[b]; break;
        case 2: m->out[i] = m->E[E_MECH_LIMIT] - fabs(Q[a]); break;
        default: m->out[i] = su_record(m, a, b); break;
        }
    }
    m->valid = 1;
}

/* ---------------------------------------------------------------- FMI: common */

const char *fmi2GetTypesPlatform(void) { return fmi2TypesPlatform; }
const char *fmi2GetVersion(void) { return fmi2Version; }

fmi2Status fmi2SetDebugLogging(fmi2Component c, fmi2Boolean loggingOn, size_t nCategories,
                               const fmi2String categories[])
{
    (void)nCategories; (void)categories;
    ((Inst *)c)->logging = loggingOn ? 1 : 0;
    return fmi2OK;
}

static void su_reset(Inst *m)
{
    int i;
    for (i = 0; i < SU_NPAR; i++) m->par[i] = su_par0[i];
    memset(m->y, 0, sizeof m->y);
    memset(m->u_set, 0, sizeof m->u_set);
    memset(m->du_set, 0, sizeof m->du_set);
    memset(m->d2u_set, 0, sizeof m->d2u_set);
    m->t_set = 0.0;
    m->time = 0.0;
    m->k = 0;
    m->sampled = 0;
    m->diverged = 0;
    m->phase = PH_INSTANTIATED;
    su_entries(m);
}

fmi2Component fmi2Instantiate(fmi2String instanceName, fmi2Type fmuType, fmi2String fmuGUID,
                              fmi2String fmuResourceLocation,
                              const fmi2CallbackFunctions *functions, fmi2Boolean visible,
                              fmi2Boolean loggingOn)
{
    Inst *m;
    (void)fmuResourceLocation; (void)visible;
    if (fmuGUID == NULL || strcmp(fmuGUID, SU_GUID) != 0) {
        if (functions && functions->logger)
            functions->logger(functions->componentEnvironment, instanceName, fmi2Error,
                              "logStatusError", "the GUID %s is not this FMU's (%s)",
                              fmuGUID ? fmuGUID : "(none)", SU_GUID);
        return NULL;
    }
    m = (Inst *)calloc(1, sizeof(Inst));
    if (m == NULL) return NULL;
    m->cb = functions;
    snprintf(m->name, sizeof m->name, "%s", instanceName ? instanceName : "suspopt");
    m->cs = fmuType == fmi2CoSimulation;
    m->logging = loggingOn ? 1 : 0;
    su_reset(m);
    return m;
}

void fmi2FreeInstance(fmi2Component c)
{
    Inst *m = (Inst *)c;
    if (m == NULL) return;
    free(m->history);
    free(m);
}

fmi2Status fmi2SetupExperiment(fmi2Component c, fmi2Boolean toleranceDefined, fmi2Real tolerance,
                               fmi2Real startTime, fmi2Boolean stopTimeDefined, fmi2Real stopTime)
{
    Inst *m = (Inst *)c;
    (void)toleranceDefined; (void)tolerance;
    if (startTime != 0.0) return su_fail(m, "%s", "the model starts at rest at t = 0: startTime must be 0");
#if SU_EMBEDDED
    if (stopTimeDefined && stopTime > SU_ROAD_END * (1.0 + 1e-12))
        return su_fail(m, "%s", "the road built into this FMU ends at the config's duration "
                                "(DefaultExperiment stopTime); export with --road input for longer runs");
#else
    (void)stopTimeDefined; (void)stopTime;
#endif
    return fmi2OK;
}

fmi2Status fmi2EnterInitializationMode(fmi2Component c)
{
    ((Inst *)c)->phase = PH_INIT;
    return fmi2OK;
}

fmi2Status fmi2ExitInitializationMode(fmi2Component c)
{
    Inst *m = (Inst *)c;
    su_entries(m);
    su_controller_start(m);
    m->k = 0;
    m->time = 0.0;
    m->sampled = 0;
    m->next_control = 0;
    m->next_edge = 0;
#if SU_EMBEDDED
    if (m->cs) {
        int i;
        for (i = 0; i < SU_NSTART_KICKS; i++) su_impulse(m, su_start_kicks[i]);
    }
#endif
    m->valid = 0;
    m->phase = m->cs ? PH_STEP : PH_EVENT;
    return fmi2OK;
}

fmi2Status fmi2Terminate(fmi2Component c)
{
    ((Inst *)c)->phase = PH_TERMINATED;
    return fmi2OK;
}

fmi2Status fmi2Reset(fmi2Component c)
{
    Inst *m = (Inst *)c;
    m->hist_n = 0;
    su_reset(m);
    return fmi2OK;
}

fmi2Status fmi2GetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, fmi2Real value[])
{
    Inst *m = (Inst *)c;
    size_t i;
    if (m->dirty) su_entries(m);
    for (i = 0; i < nvr; i++) {
        fmi2ValueReference v = vr[i];
        if (v < VR_IN) value[i] = m->par[v];
        else if (v < VR_OUT) {
            int j = (int)(v - VR_IN);
            value[i] = m->u_set[su_in_slot[j]];
        } else if (v < VR_Q) {
            su_outputs(m);
            value[i] = m->out[v - VR_OUT];
        } else if (v < VR_A) value[i] = m->y[v - VR_Q];
        else if (v < VR_END) {
            su_outputs(m);
            value[i] = m->a[v - VR_A];
        } else return su_fail(m, "%s", "fmi2GetReal: no such value reference");
    }
    return fmi2OK;
}

fmi2Status fmi2SetReal(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                       const fmi2Real value[])
{
    Inst *m = (Inst *)c;
    size_t i;
    for (i = 0; i < nvr; i++) {
        fmi2ValueReference v = vr[i];
        if (v < VR_IN) {
            if (!su_tunable[v]) {
                if (value[i] == su_par0[v]) continue;
                return su_fail(m, "%s is a constant of this FMU (exported with the design's "
                                  "value: see its description)", su_par_name[v]);
            }
            m->par[v] = value[i];
            m->dirty = 1;
        } else if (v < VR_OUT) {
            int j = (int)(v - VR_IN);
            m->u_set[su_in_slot[j]] = value[i];
            m->du_set[su_in_slot[j]] = 0.0;
            m->d2u_set[su_in_slot[j]] = 0.0;
            m->t_set = m->time;
        } else return su_fail(m, "%s", "fmi2SetReal: only parameters and inputs can be set");
    }
    m->valid = 0;
    return fmi2OK;
}

#define SU_NO_VARIABLES(name, type)                                                       \
    fmi2Status name(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, type value[]) \
    {                                                                                     \
        (void)vr; (void)value;                                                            \
        return nvr ? su_fail((Inst *)c, "%s", #name ": this FMU has none") : fmi2OK;       \
    }
SU_NO_VARIABLES(fmi2GetInteger, fmi2Integer)
SU_NO_VARIABLES(fmi2GetBoolean, fmi2Boolean)
SU_NO_VARIABLES(fmi2GetString, fmi2String)
#define SU_NO_SET(name, type)                                                                   \
    fmi2Status name(fmi2Component c, const fmi2ValueReference vr[], size_t nvr, const type value[]) \
    {                                                                                           \
        (void)vr; (void)value;                                                                  \
        return nvr ? su_fail((Inst *)c, "%s", #name ": this FMU has none") : fmi2OK;             \
    }
SU_NO_SET(fmi2SetInteger, fmi2Integer)
SU_NO_SET(fmi2SetBoolean, fmi2Boolean)
SU_NO_SET(fmi2SetString, fmi2String)

fmi2Status fmi2GetFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)s; return su_fail((Inst *)c, "%s", "no FMU state"); }
fmi2Status fmi2SetFMUstate(fmi2Component c, fmi2FMUstate s) { (void)s; return su_fail((Inst *)c, "%s", "no FMU state"); }
fmi2Status fmi2FreeFMUstate(fmi2Component c, fmi2FMUstate *s) { (void)s; return su_fail((Inst *)c, "%s", "no FMU state"); }
fmi2Status fmi2SerializedFMUstateSize(fmi2Component c, fmi2FMUstate s, size_t *n) { (void)s; (void)n; return su_fail((Inst *)c, "%s", "no FMU state"); }
fmi2Status fmi2SerializeFMUstate(fmi2Component c, fmi2FMUstate s, fmi2Byte b[], size_t n) { (void)s; (void)b; (void)n; return su_fail((Inst *)c, "%s", "no FMU state"); }
fmi2Status fmi2DeSerializeFMUstate(fmi2Component c, const fmi2Byte b[], size_t n, fmi2FMUstate *s) { (void)s; (void)b; (void)n; return su_fail((Inst *)c, "%s", "no FMU state"); }

fmi2Status fmi2GetDirectionalDerivative(fmi2Component c, const fmi2ValueReference u[], size_t nu,
                                        const fmi2ValueReference z[], size_t nz,
                                        const fmi2Real dv[], fmi2Real dz[])
{
    (void)u; (void)nu; (void)z; (void)nz; (void)dv; (void)dz;
    return su_fail((Inst *)c, "%s", "directional derivatives are not provided");
}

/* ---------------------------------------------------------------- FMI: model exchange */

fmi2Status fmi2EnterEventMode(fmi2Component c)
{
    ((Inst *)c)->phase = PH_EVENT;
    return fmi2OK;
}

static int su_at(double t, double when, double dt) { return fabs(t - when) <= 1e-9 * dt; }

fmi2Status fmi2NewDiscreteStates(fmi2Component c, fmi2EventInfo *info)
{
    /* the time events at m->time: the road's edges (their impulses), then the controller's
       step (its sample when due, the lag), as a co-simulation step starts */
    Inst *m = (Inst *)c;
    const double dt = m->E[E_DT];
    double next = INFINITY;
    info->newDiscreteStatesNeeded = fmi2False;
    info->terminateSimulation = fmi2False;
    info->nominalsOfContinuousStatesChanged = fmi2False;
    info->valuesOfContinuousStatesChanged = fmi2False;
    if (m->dirty) su_entries(m);
#if SU_EMBEDDED
    while (m->next_edge < SU_NEDGES && m->E[E_EDGE_TIME + m->next_edge] <= m->time + 1e-9 * dt) {
        su_impulse(m, m->next_edge++);
        info->valuesOfContinuousStatesChanged = fmi2True;
    }
    if (m->next_edge < SU_NEDGES) next = m->E[E_EDGE_TIME + m->next_edge];
#endif
#if SU_CONTROLLED
    while ((double)m->next_control * dt <= m->time + 1e-9 * dt) {
        if (su_at(m->time, (double)m->next_control * dt, dt))
            su_control(m, m->next_control, su_road_at(m, m->time));
        m->next_control += SU_LAGGED ? 1 : SU_EVERY;
    }
    if ((double)m->next_control * dt < next) next = (double)m->next_control * dt;
#endif
    info->nextEventTimeDefined = isfinite(next) ? fmi2True : fmi2False;
    info->nextEventTime = isfinite(next) ? next : 0.0;
    m->valid = 0;
    return fmi2OK;
}

fmi2Status fmi2EnterContinuousTimeMode(fmi2Component c)
{
    ((Inst *)c)->phase = PH_CONTINUOUS;
    return fmi2OK;
}

fmi2Status fmi2CompletedIntegratorStep(fmi2Component c, fmi2Boolean noSetFMUStatePriorToCurrentPoint,
                                       fmi2Boolean *enterEventMode, fmi2Boolean *terminateSimulation)
{
    Inst *m = (Inst *)c;
    (void)noSetFMUStatePriorToCurrentPoint;
    *enterEventMode = fmi2False;
    *terminateSimulation = fmi2False;
    {
        int i;
        for (i = 0; i < N2; i++)
            if (!(fabs(m->y[i]) < SU_LIMIT)) {
                su_log(m, fmi2Error, "logStatusError", "the design diverged at t = %g s", m->time);
                *terminateSimulation = fmi2True;
            }
    }
    return fmi2OK;
}

fmi2Status fmi2SetTime(fmi2Component c, fmi2Real time)
{
    Inst *m = (Inst *)c;
    m->time = time; /* (past the embedded road's end, its last value holds: su_road_at) */
    m->valid = 0;
    return fmi2OK;
}

fmi2Status fmi2SetContinuousStates(fmi2Component c, const fmi2Real x[], size_t nx)
{
    Inst *m = (Inst *)c;
    if (nx != N2) return su_fail(m, "%s", "fmi2SetContinuousStates: wrong number of states");
    memcpy(m->y, x, sizeof(double) * N2);
    m->valid = 0;
    return fmi2OK;
}

fmi2Status fmi2GetDerivatives(fmi2Component c, fmi2Real derivatives[], size_t nx)
{
    Inst *m = (Inst *)c;
    if (nx != N2) return su_fail(m, "%s", "fmi2GetDerivatives: wrong number of states");
    if (m->dirty) su_entries(m);
    su_slope(m, m->y, su_road_at(m, m->time), 0.0, derivatives);
    return fmi2OK;
}

fmi2Status fmi2GetEventIndicators(fmi2Component c, fmi2Real indicators[], size_t ni)
{
    (void)indicators;
    return ni ? su_fail((Inst *)c, "%s", "this FMU has no event indicators") : fmi2OK;
}

fmi2Status fmi2GetContinuousStates(fmi2Component c, fmi2Real x[], size_t nx)
{
    Inst *m = (Inst *)c;
    if (nx != N2) return su_fail(m, "%s", "fmi2GetContinuousStates: wrong number of states");
    memcpy(x, m->y, sizeof(double) * N2);
    return fmi2OK;
}

fmi2Status fmi2GetNominalsOfContinuousStates(fmi2Component c, fmi2Real x_nominal[], size_t nx)
{
    size_t i;
    (void)c;
    for (i = 0; i < nx; i++) x_nominal[i] = 1.0;
    return fmi2OK;
}

/* ---------------------------------------------------------------- FMI: co-simulation */

fmi2Status fmi2SetRealInputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                       const fmi2Integer order[], const fmi2Real value[])
{
    Inst *m = (Inst *)c;
    size_t i;
    for (i = 0; i < nvr; i++) {
        if (vr[i] < VR_IN || vr[i] >= VR_OUT || order[i] < 1 || order[i] > 2)
            return su_fail(m, "%s", "fmi2SetRealInputDerivatives: first and second derivatives "
                                    "of inputs only");
        if (order[i] == 1) m->du_set[su_in_slot[vr[i] - VR_IN]] = value[i];
        else m->d2u_set[su_in_slot[vr[i] - VR_IN]] = value[i];
    }
    m->valid = 0;
    return fmi2OK;
}

fmi2Status fmi2GetRealOutputDerivatives(fmi2Component c, const fmi2ValueReference vr[], size_t nvr,
                                        const fmi2Integer order[], fmi2Real value[])
{
    (void)vr; (void)order; (void)value;
    return nvr ? su_fail((Inst *)c, "%s", "output derivatives are not provided") : fmi2OK;
}

fmi2Status fmi2DoStep(fmi2Component c, fmi2Real currentCommunicationPoint,
                      fmi2Real communicationStepSize, fmi2Boolean noSetFMUStatePriorToCurrentPoint)
{
    Inst *m = (Inst *)c;
    const double dt = m->E[E_DT];
    double steps_real = communicationStepSize / dt;
    long steps = (long)floor(steps_real + 0.5), s;
    (void)noSetFMUStatePriorToCurrentPoint;
    if (m->dirty) su_entries(m);
    if (fabs(currentCommunicationPoint - m->time) > 1e-9 * dt)
        return su_fail(m, "%s", "fmi2DoStep: the communication point is not this FMU's time");
    if (steps < 1 || fabs(steps_real - (double)steps) > 1e-6)
        return su_fail(m, "%s", "fmi2DoStep: the communication step must be a whole multiple of "
                                "the config's dt (DefaultExperiment stepSize)");
#if SU_EMBEDDED
    if (m->k + steps > SU_STEPS)
        return su_fail(m, "%s", "fmi2DoStep: the road built into this FMU ends at the config's "
                                "duration; export with --road input for longer runs");
#endif
    for (s = 0; s < steps; s++) {
        if (!su_cs_step(m)) {
            m->diverged = 1;
            su_log(m, fmi2Error, "logStatusError", "the design diverged at t = %g s", m->time);
            return fmi2Error;
        }
    }
    return fmi2OK;
}

fmi2Status fmi2CancelStep(fmi2Component c) { return su_fail((Inst *)c, "%s", "fmi2DoStep never runs asynchronously"); }

fmi2Status fmi2GetStatus(fmi2Component c, const fmi2StatusKind s, fmi2Status *value)
{
    (void)s;
    *value = ((Inst *)c)->diverged ? fmi2Error : fmi2OK;
    return fmi2OK;
}

fmi2Status fmi2GetRealStatus(fmi2Component c, const fmi2StatusKind s, fmi2Real *value)
{
    if (s != fmi2LastSuccessfulTime) return fmi2Discard;
    *value = ((Inst *)c)->time;
    return fmi2OK;
}

fmi2Status fmi2GetIntegerStatus(fmi2Component c, const fmi2StatusKind s, fmi2Integer *value)
{
    (void)c; (void)s; (void)value;
    return fmi2Discard;
}

fmi2Status fmi2GetBooleanStatus(fmi2Component c, const fmi2StatusKind s, fmi2Boolean *value)
{
    (void)c;
    if (s != fmi2Terminated) return fmi2Discard;
    *value = fmi2False;
    return fmi2OK;
}

fmi2Status fmi2GetStringStatus(fmi2Component c, const fmi2StatusKind s, fmi2String *value)
{
    (void)c; (void)s; (void)value;
    return fmi2Discard;
}
