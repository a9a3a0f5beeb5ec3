/* The whole physics step of the rovers in C: wheel and tyre forces, grip, body I/O, the
 * Chipmunk step and the safety check, for amsa_phys.physics.compiled.
 *
 * Why: in a headless run the Python force model, the body reads and writes and the step's
 * Python layer were two thirds of the loop; this file does the same work in one call.
 *
 * Same numbers, bit for bit: every expression below is forces.py's (rover_step, which
 * fewrovers.FewRovers.apply calls, and the rare branches in wheel.py), written in the same order with C doubles. CPython's floats are
 * C doubles and its math.sin/cos/sqrt are libm's, so with no reassociation and no FMA
 * contraction (built with -ffp-contract=off, no -ffast-math) each result is the same double.
 * Keep it that way: change forces.py and this file together (the tests compare the traces).
 * rover_pair repeats rover_forces' usual path for two rovers at once: change both
 * (tests/physics/test_rover_pairs.py holds them to each other bit for bit).
 *
 * No second copy of Chipmunk: the Chipmunk functions are called through pointers taken from
 * pymunk's own cffi library (compiled.py passes them in), on pymunk's own bodies and space.
 * This module links against nothing but libm.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <structmember.h>
#include <math.h>

#include "../pymod.h" /* Python's float %, shared */
#include "workers.h"       /* helper threads for a batch's column step (Columns) */
#include <stdint.h>
#include <string.h>

typedef struct {
    double x, y;
} cpVect;

typedef cpVect (*get_vect_fn)(const void *);
typedef double (*get_double_fn)(const void *);
typedef void (*set_vect_fn)(void *, cpVect);
typedef void (*set_double_fn)(void *, double);
typedef void (*space_step_fn)(void *, double);

/* Per-rover constants, in this order: the layout is exported as PLAN_FIELDS (below), and
 * compiled.py fills each rover's row by these names from forces.fold, checking at import that
 * it knows every one. Add a constant here and in plan_fields together. */
enum {
    P_KP, P_C, P_FMAX, P_MW, P_BB, P_BBE, P_E, P_E2, P_KX, P_H, P_TURN_K, P_DT_I, P_DT_M,
    P_SPHI, P_KY_DT_M, P_NEG_M_DT, P_BIG_BC, P_KY, P_MASS, P_XFER, P_KMAX, P_INV_G2,
    P_C_EXP, P_BRAKE, PLAN_WIDTH
};

static const char *const plan_fields[PLAN_WIDTH] = {
    "kp", "c", "f_max", "mw", "big_b", "big_be", "e", "e2", "kx", "half_track", "turn_k",
    "dt_i", "dt_m", "sphi", "ky_dt_m", "neg_m_dt", "big_bc", "ky", "mass", "xfer", "kmax",
    "inv_g2", "c_exp", "brake",
};

#define SLIP_SPEED_MIN 0.1
/* forces.LOAD_FLOOR: a drive wheel's smallest relative load */
#define LOAD_FLOOR 1e-9
#define N_BUFFERS 7
/* The nine ground terms of a rover (forces.ground_list's order) and where a batch's (9, n)
 * ground array keeps each (fleet._GROUND_ROWS); both exported and checked at import. */
#define GROUND_TERMS 9
static const int ground_rows[GROUND_TERMS] = {0, 2, 4, 1, 3, 5, 6, 7, 8};

typedef struct {
    PyObject_HEAD
    void *space;
    get_vect_fn get_position;
    get_double_fn get_angle;
    get_vect_fn get_velocity;
    get_double_fn get_angular_velocity;
    set_vect_fn set_force;
    set_double_fn set_torque;
    space_step_fn space_step;
    set_vect_fn set_position;
    set_double_fn set_angle;
    get_vect_fn get_rotation; /* cpBodyGetRotation, or NULL: no cache (below) */
    Py_ssize_t n;
    /* buffers shared with Python (held until dealloc) */
    Py_buffer views[N_BUFFERS];
    int n_views;
    void **bodies;        /* n cpBody pointers */
    const int64_t *offsets; /* n: where rover k's six state floats start */
    const double *plan;   /* n * PLAN_WIDTH */
    const double *drives; /* (2, n): left row, right row */
    double *rims;         /* rover k's left at k*rim_k, right at k*rim_k + rim_side */
    const double *ground; /* term t of rover k at k*ground_k + ground_off[t] */
    double *state;
    Py_ssize_t rim_k, rim_side, ground_k;
    Py_ssize_t ground_off[GROUND_TERMS];
    double dt, max2, extent;
    double sub_speed; /* faster than this a step is cut into sub-steps (bodyio.substeps) */
    double top2;      /* the fastest rover's squared speed after the last step */
    /* rover k's angle and its cos and sin at 3k..3k+2: Chipmunk computed them when it set
     * the body's transform (cpBodyUpdatePosition: cos(a), sin(a) with the same libm), so
     * rover_forces takes them instead of computing them again when its state's angle is
     * the cached one bit for bit (~5 % of the step). NULL: always computed. */
    double *rot;
    /* Columns (rot_ahead set; rot then their own): the forces store each rover's predicted
     * end angle with its cos and sin (computed for the lateral force) in rot, and the
     * integration keeps them where it lands on that angle bit for bit, else computes them
     * (Columns_move_range). Why: ~3 steps in 4 land on it, and the angle's cos and sin were
     * ~9 % of a batch's physics. A pure function of the angle: the same doubles either way,
     * and the forces still take rot only where its angle is their state's bit for bit. */
    int rot_ahead;
    /* each rover's vx, vy, w before the Chipmunk step under way (3k..3k+2): the trapezoid's
     * other end (second_order below) */
    double *v0;
    Py_ssize_t batch_i; /* advance_many: the step under way (0: the first) */
    int stop;           /* advance_many: end after the step under way */
    /* the bodies' fields read (and the position written) in place, at the offsets below,
     * instead of through Chipmunk's getters and cpBodySetPosition: bodylayout.body_layout_ok
     * confirmed the layout in this process (0: every access a call) */
    int direct;
} Stepper;

/* Where Chipmunk's cpBody keeps what the step reads (chipmunk_structs.h, Chipmunk 7 and
 * pymunk's Munk2D alike: two function pointers, m, m_inv, i, i_inv, then cog, p, v, f, a,
 * w, t, transform {a, b, c, d, tx, ty}). Used only where bodylayout.body_layout_ok found every
 * one of them where a getter says it is (``body_fields`` below reads them for it). Why:
 * a 1,000-rover step made ~17 calls a rover into Chipmunk's getters and setters, and
 * cpBodySetPosition's own transform (a sincos) is overwritten by cpBodySetAngle's at once. */
#define BODY_COG 48
#define BODY_P 64
#define BODY_V 80
#define BODY_A 112
#define BODY_W 120
#define BODY_T 136

static inline const double *body_at(const void *body, size_t offset)
{
    return (const double *)((const char *)body + offset);
}

/* cpBodyGetPosition: cpTransformPoint(body->transform, cpvzero), the same operations */
static inline cpVect body_position(const void *body)
{
    const double *t = body_at(body, BODY_T);
    cpVect p = {t[0] * 0.0 + t[2] * 0.0 + t[4], t[1] * 0.0 + t[3] * 0.0 + t[5]};
    return p;
}

/* ---- wheel.py's rare branches --------------------------------------------------------- */
typedef struct {
    double mw, c, f_max, big_b, big_bc, e, e2;
} StepConstants;

static void solve_one(double u, double v, double f0, double fr, double k, const StepConstants *s,
                      double *fx_out, double *up_out)
{ /* wheel._solve */
    double a = (s->mw * u + f0 - fr) * s->big_b;
    double fx = k * (a - v) / (1.0 + k * (s->big_b + s->e));
    double up = a - s->big_b * fx;
    double fm = f0 - s->c * up;
    if (fm > s->f_max || fm < -s->f_max) {
        double lim = fm > 0 ? s->f_max : -s->f_max;
        a = u + (lim - fr) * s->big_bc;
        fx = k * (a - v) / (1.0 + k * (s->big_bc + s->e));
        up = a - s->big_bc * fx;
    }
    *fx_out = fx;
    *up_out = up;
}

static double limited(double f0, const StepConstants *s)
{
    return (-s->f_max <= f0 && f0 <= s->f_max) ? f0 : (f0 > 0 ? s->f_max : -s->f_max);
}

static void rim_and_tyre(double u, double v, double f0, double res, double k,
                         const StepConstants *s, double *fx_out, double *up_out)
{ /* wheel.rim_and_tyre */
    if (u != 0.0) {
        double fx, up;
        solve_one(u, v, f0, u > 0 ? res : -res, k, s, &fx, &up);
        if (up * u > 0.0) {
            *fx_out = fx;
            *up_out = up;
            return;
        }
    }
    double fx = -k * v / (1.0 + k * s->e);
    double f0_lim = limited(f0, s);
    double need = f0_lim + s->mw * u - fx;
    if (-res <= need && need <= res) {
        *fx_out = fx;
        *up_out = 0.0;
        return;
    }
    solve_one(u, v, f0, need > 0 ? res : -res, k, s, fx_out, up_out);
}

static void joint(const double u[2], const double v[2], const double f0[2], const double fr[2],
                  const double k[2], const int lim[2], const StepConstants *s, double out[4])
{ /* wheel.joint */
    double a[2], bw[2];
    for (int i = 0; i < 2; i++) {
        if (lim[i]) {
            a[i] = u[i] + ((double)lim[i] * s->f_max - fr[i]) * s->big_bc;
            bw[i] = s->big_bc;
        } else {
            a[i] = (s->mw * u[i] + f0[i] - fr[i]) * s->big_b;
            bw[i] = s->big_b;
        }
    }
    double gl = 1.0 + k[0] * (bw[0] + s->e);
    double gr = 1.0 + k[1] * (bw[1] + s->e);
    double cl = k[0] * s->e2;
    double cr = k[1] * s->e2;
    double bl = k[0] * (a[0] - v[0]);
    double br = k[1] * (a[1] - v[1]);
    double det = gl * gr - cl * cr;
    double fxl = (bl * gr - cl * br) / det;
    double fxr = (br * gl - cr * bl) / det;
    out[0] = fxl;
    out[1] = a[0] - bw[0] * fxl;
    out[2] = fxr;
    out[3] = a[1] - bw[1] * fxr;
}

static int held_by(double f0, double fx, double res, const StepConstants *s)
{
    double f0_lim = limited(f0, s);
    double d = f0_lim - fx;
    return -res <= d && d <= res;
}

static void wheel_pair(const double u[2], const double v[2], const double f0[2],
                       const double res[2], const double k[2], const StepConstants *s,
                       double out[4])
{ /* wheel.wheel_pair: (F_xL, u_L+, F_xR, u_R+) */
    double ul = u[0], ur = u[1];
    if (ul == 0.0 && ur == 0.0) { /* wheel.held */
        double gl = 1.0 + k[0] * s->e;
        double gr = 1.0 + k[1] * s->e;
        double cl = k[0] * s->e2;
        double cr = k[1] * s->e2;
        double bl = -k[0] * v[0];
        double br = -k[1] * v[1];
        double det = gl * gr - cl * cr;
        double fxl = (bl * gr - cl * br) / det;
        double fxr = (br * gl - cr * bl) / det;
        if (held_by(f0[0], fxl, res[0], s) && held_by(f0[1], fxr, res[1], s)) {
            out[0] = fxl;
            out[1] = 0.0;
            out[2] = fxr;
            out[3] = 0.0;
            return;
        }
    }
    double fr[2] = {
        ul > 0.0 ? res[0] : (ul < 0.0 ? -res[0] : 0.0),
        ur > 0.0 ? res[1] : (ur < 0.0 ? -res[1] : 0.0),
    };
    int lim[2] = {0, 0};
    double r[4];
    for (int pass = 0; pass < 3; pass++) {
        joint(u, v, f0, fr, k, lim, s, r);
        int nw[2];
        double fm[2] = {f0[0] - s->c * r[1], f0[1] - s->c * r[3]};
        for (int i = 0; i < 2; i++)
            nw[i] = lim[i] ? lim[i] : (fm[i] > s->f_max ? 1 : (fm[i] < -s->f_max ? -1 : 0));
        if (nw[0] == lim[0] && nw[1] == lim[1])
            break;
        lim[0] = nw[0];
        lim[1] = nw[1];
    }
    if (r[1] * ul > 0.0 && r[3] * ur > 0.0) {
        out[0] = r[0];
        out[1] = r[1];
        out[2] = r[2];
        out[3] = r[3];
        return;
    }
    double fxl, upl, fxr, upr;
    rim_and_tyre(ul, v[0], f0[0], res[0], k[0], s, &fxl, &upl);
    rim_and_tyre(ur, v[1], f0[1], res[1], k[1], s, &fxr, &upr);
    for (int pass = 0; pass < 2; pass++) {
        double nfxl, nupl, nfxr, nupr;
        rim_and_tyre(ul, v[0] + s->e2 * fxr, f0[0], res[0], k[0], s, &nfxl, &nupl);
        rim_and_tyre(ur, v[1] + s->e2 * fxl, f0[1], res[1], k[1], s, &nfxr, &nupr);
        fxl = nfxl;
        upl = nupl;
        fxr = nfxr;
        upr = nupr;
    }
    out[0] = fxl;
    out[1] = upl;
    out[2] = fxr;
    out[3] = upr;
}

/* ---- sliding.slide: a sliding tyre solved with its rim ----------------------------------- */
#define SLIDE_ITERATIONS 100

typedef struct {
    double u, v, f0, res, ivs, kx, ix, qy;
    const StepConstants *s;
} Slide;

static double slide_tyre_x(const Slide *w, double up, double *scale)
{
    double fx = w->kx * (0.5 * (w->u + up) - w->v) * w->ivs;
    double qx = fx * w->ix;
    double qq = qx * qx + w->qy * w->qy;
    *scale = qq > 1.0 ? 1.0 / sqrt(qq) : 1.0;
    return fx * *scale;
}

static double slide_excess(const Slide *w, double up, double fr)
{
    const StepConstants *s = w->s;
    double fm = w->f0 - s->c * up;
    if (fm > s->f_max)
        fm = s->f_max;
    else if (fm < -s->f_max)
        fm = -s->f_max;
    if (up * w->u < 0.0) /* through zero within the step: the resistance's mean over the path */
        fr = w->res * (fabs(up) - fabs(w->u)) / (up - w->u);
    double scale;
    double fx = slide_tyre_x(w, up, &scale);
    return s->mw * (up - w->u) - fm + fr + fx;
}

static void slide_once(double u, double v, double f0, double res, double ivs, double kx,
                       double ky, double ix, double iy, double side, double fy_cap,
                       const StepConstants *s, double *fx_out, double *fy_out, double *up_out)
{
    Slide w = {u, v, f0, res, ivs, kx, ix, -ky * side * ivs * iy, s};
    double scale;
    double up;
    double rest = limited(f0, s) - slide_tyre_x(&w, 0.0, &scale);
    double need = s->mw * u + rest;
    /* the side the rim ends on: it keeps its direction, or stops within the step */
    double side_up;
    if (u > 0.0)
        side_up = need > res ? 1.0 : -1.0;
    else if (u < 0.0)
        side_up = need < -res ? -1.0 : 1.0;
    else
        side_up = need > res ? 1.0 : (need < -res ? -1.0 : 0.0);
    if (side_up * u <= 0.0 && -res <= rest && rest <= res) {
        up = 0.0; /* at rest, or stopped within the step, and the resistance holds it */
    } else {
        double reach = (s->f_max + 1.0 / ix) / s->mw;
        if (side_up * u < 0.0) /* through zero: the mean resistance lets it go R further */
            reach = reach + res / s->mw;
        double lo, hi, fr;
        if (side_up > 0.0) {
            lo = 0.0, hi = u + reach, fr = res;
        } else {
            lo = u - reach, hi = 0.0, fr = -res;
        }
        for (int i = 0; i < SLIDE_ITERATIONS; i++) {
            double mid = 0.5 * (lo + hi);
            if (mid <= lo || mid >= hi)
                break;
            if (slide_excess(&w, mid, fr) > 0.0)
                hi = mid;
            else
                lo = mid;
        }
        up = 0.5 * (lo + hi);
    }
    double fx = slide_tyre_x(&w, up, &scale);
    double fy = -ky * side * ivs * scale;
    if (fabs(fy_cap) < fabs(fy))
        fy = fy_cap;
    *fx_out = fx;
    *fy_out = fy;
    *up_out = up;
}

#define SPLIT_MIN 0.02

/* sliding.slide: one solve, split where the rim passes its hub's speed within the step */
static void slide(double u, double v, double f0, double res, double ivs, double kx, double ky,
                  double ix, double iy, double side, double fy_cap, const StepConstants *s,
                  double *fx_out, double *fy_out, double *up_out)
{
    double fx, fy, up;
    slide_once(u, v, f0, res, ivs, kx, ky, ix, iy, side, fy_cap, s, &fx, &fy, &up);
    double a = u - v;
    double b = up - v;
    if (a * b < 0.0) {
        double tau = a / (a - b);
        if (SPLIT_MIN < tau && tau < 1.0 - SPLIT_MIN) {
            StepConstants s1 = *s;
            StepConstants s2 = *s;
            s1.mw = s->mw / tau;
            s2.mw = s->mw / (1.0 - tau);
            double fx1, fy1, u1, fx2, fy2;
            slide_once(u, v, f0, res, ivs, kx, ky, ix, iy, side, fy_cap, &s1, &fx1, &fy1, &u1);
            slide_once(u1, v, f0, res, ivs, kx, ky, ix, iy, side, fy_cap, &s2, &fx2, &fy2, &up);
            fx = tau * fx1 + (1.0 - tau) * fx2;
            fy = tau * fy1 + (1.0 - tau) * fy2;
        }
    }
    *fx_out = fx;
    *fy_out = fy;
    *up_out = up;
}

/* ---- scrub.patch_scrub: both patches' turn-slip moment, each capped at its own torque -- */
static double patch_scrub(double w, double torque, double kl, double kr, double ksum, double tl,
                          double tr, double ts, double dt_i)
{
    double base = w + torque * dt_i;
    double scrub = -ksum * base / (1.0 + ksum * dt_i);
    double wn = base / (1.0 + ksum * dt_i);
    double ql = kl * wn, qr = kr * wn;
    if (-tl <= ql && ql <= tl && -tr <= qr && qr <= tr)
        return scrub;
    double k2, t1, t2;
    if (kl * tr >= kr * tl) {
        t1 = tl, k2 = kr, t2 = tr;
    } else {
        t1 = tr, k2 = kl, t2 = tl;
    }
    double s1 = base > 0.0 ? -t1 : t1;
    wn = (base + s1 * dt_i) / (1.0 + k2 * dt_i);
    double s2 = -k2 * wn;
    if (s2 > t2 || s2 < -t2)
        return base > 0.0 ? -ts : ts;
    return s1 + s2;
}

/* ---- sliding.slide_pair and sliding.mid_step ------------------------------------------ */
typedef struct {
    double ul, vl, f0l, rl, ivl, ixl, iyl, ur, vr, f0r, rr, ivr, ixr, iyr, kx, ky, ky_dt_m,
        cancel;
    const StepConstants *s;
} SlideIn;

/* grip: the gripping solve's (F_xL, F_yL, u_L+, F_xR, F_yR, u_R+); hub: the sliding tyres'
 * (v_L, 1/s_L, v_R, 1/s_R, v_side); out as grip */
static void slide_pair(const SlideIn *in, int sat_l, int sat_r, const double grip[6],
                       const double hub[5], double out[6])
{
    const StepConstants sc = *in->s;
    const double ul = in->ul, vl = in->vl, f0l = in->f0l, rl = in->rl, ivl = in->ivl;
    const double ixl = in->ixl, iyl = in->iyl, ur = in->ur, vr = in->vr, f0r = in->f0r;
    const double rr = in->rr, ivr = in->ivr, ixr = in->ixr, iyr = in->iyr, kx = in->kx;
    const double ky = in->ky, ky_dt_m = in->ky_dt_m, cancel = in->cancel;
    const double ml = hub[0], jl = hub[1], mr = hub[2], jr = hub[3], side0 = hub[4];
    double fxl = grip[0], fyl = grip[1], upl = grip[2], fxr = grip[3], fyr = grip[4],
           upr = grip[5];
    double t1, t2, t3, t4;
        if (sat_l)
            slide(ul, ml, f0l, rl, jl, kx, ky, ixl, iyl, side0, cancel, &sc, &fxl, &fyl, &upl);
        if (sat_r)
            slide(ur, mr, f0r, rr, jr, kx, ky, ixr, iyr, side0, cancel, &sc, &fxr, &fyr, &upr);
        if (sat_l && !sat_r)
            rim_and_tyre(ur, vr + sc.e2 * fxl, f0r, rr, kx * ivr, &sc, &fxr, &upr);
        else if (sat_r && !sat_l)
            rim_and_tyre(ul, vl + sc.e2 * fxr, f0l, rl, kx * ivl, &sc, &fxl, &upl);
        if (!sat_r) {
            double kg = ky_dt_m * ivr;
            fyr = (cancel - fyl) * kg / (1.0 + kg);
            t3 = fxr * ixr;
            t4 = fyr * iyr;
            if (t3 * t3 + t4 * t4 > 1.0) {
                sat_r = 1;
                slide(ur, mr, f0r, rr, jr, kx, ky, ixr, iyr, side0, cancel, &sc, &fxr, &fyr,
                      &upr);
            }
        } else if (!sat_l) {
            double kg = ky_dt_m * ivl;
            fyl = (cancel - fyr) * kg / (1.0 + kg);
            t1 = fxl * ixl;
            t2 = fyl * iyl;
            if (t1 * t1 + t2 * t2 > 1.0) {
                sat_l = 1;
                slide(ul, ml, f0l, rl, jl, kx, ky, ixl, iyl, side0, cancel, &sc, &fxl, &fyl,
                      &upl);
            }
        }
        if (sat_l && sat_r) {
            double fsum = fyl + fyr;
            if (fsum * cancel > 0.0 && fabs(fsum) > fabs(cancel)) {
                double q = cancel / fsum;
                fyl = fyl * q;
                fyr = fyr * q;
            }
        }
    out[0] = fxl, out[1] = fyl, out[2] = upl, out[3] = fxr, out[4] = fyr, out[5] = upr;
}

static void mid_step(double vx, double vy, double w, double angle, double qx, double qy,
                     double torque, double dt, double dt_m, double dt_i, double turn_k, double h,
                     double hub[5])
{
    double hv = 0.5 * dt_m;
    double mx = vx + qx * hv;
    double my = vy + qy * hv;
    double wm = w + 0.5 * torque * dt_i;
    double th = angle + 0.5 * w * dt + 0.25 * torque * turn_k;
    double c = cos(th);
    double s = sin(th);
    double mf = mx * c + my * s;
    double ml = mf - wm * h;
    double mr = mf + wm * h;
    const double vmin = SLIP_SPEED_MIN;
    hub[0] = ml;
    hub[1] = ml > vmin ? 1.0 / ml : (ml < -vmin ? -1.0 / ml : 1.0 / vmin);
    hub[2] = mr;
    hub[3] = mr > vmin ? 1.0 / mr : (mr < -vmin ? -1.0 / mr : 1.0 / vmin);
    hub[4] = my * c - mx * s;
}

/* ---- forces.rover_step, one rover ------------------------------------------------------ */
static inline int same_bits(double a, double b)
{
    return memcmp(&a, &b, sizeof a) == 0;
}

static void rover_forces(Stepper *st, Py_ssize_t k, double out[3])
{
    const double *p = st->plan + k * PLAN_WIDTH;
    /* no offsets (column_forces): rover k's state is row k of an (n, 6) array */
    const double *state = st->state + (st->offsets ? st->offsets[k] : 6 * k);
    const double *g = st->ground + k * st->ground_k;
    double *rim_l = st->rims + k * st->rim_k;
    double *rim_r = rim_l + st->rim_side;
    const double dt = st->dt;
    const double kp = p[P_KP], c = p[P_C], fmax = p[P_FMAX], mw = p[P_MW], bb = p[P_BB];
    const double bbe = p[P_BBE], e = p[P_E], e2 = p[P_E2], kx = p[P_KX], h = p[P_H];
    const double turn_k = p[P_TURN_K], dt_i = p[P_DT_I], dt_m = p[P_DT_M], sphi = p[P_SPHI];
    const double ky_dt_m = p[P_KY_DT_M], neg_m_dt = p[P_NEG_M_DT];
    const StepConstants sc = {mw, c, fmax, bb, p[P_BIG_BC], e, e2};
    const double vmin = SLIP_SPEED_MIN, ivmin = 1.0 / SLIP_SPEED_MIN;
    const Py_ssize_t *go = st->ground_off;
    double ixl = g[go[0]], iyl = g[go[1]];
    double rl = g[go[2]];
    double ixr = g[go[3]], iyr = g[go[4]];
    double rr = g[go[5]];
    const double ts = g[go[6]];

    double angle = state[2], vx = state[3], vy = state[4], w = state[5];
    const double gax = g[go[7]], gay = g[go[8]];
    const int sloped = gax != 0.0 || gay != 0.0;
    if (sloped) { /* the solves see the velocity gravity gives the body within the step */
        vx = vx + gax * dt;
        vy = vy + gay * dt;
    }
    double co, si;
    if (st->rot != NULL && same_bits(st->rot[3 * k], angle)) {
        co = st->rot[3 * k + 1];
        si = st->rot[3 * k + 2];
    } else {
        co = cos(angle);
        si = sin(angle);
    }
    double v_fwd = vx * co + vy * si;
    double wh = w * h;
    double ul = *rim_l, ur = *rim_r;
    double vl = v_fwd - wh;
    double vr = v_fwd + wh;
    double ivl = vl > vmin ? 1.0 / vl : (vl < -vmin ? -1.0 / vl : ivmin);
    double ivr = vr > vmin ? 1.0 / vr : (vr < -vmin ? -1.0 / vr : ivmin);
    double kl = kx * ivl;
    double kr = kx * ivr;
    double f0l = kp * st->drives[k] - p[P_C_EXP] * ul;
    double f0r = kp * st->drives[st->n + k] - p[P_C_EXP] * ur;
    const double brake = p[P_BRAKE];
    if (brake != 0.0) { /* the holding brake (forces.rover_step) */
        if (st->drives[k] == 0.0)
            rl = rl + brake;
        if (st->drives[st->n + k] == 0.0)
            rr = rr + brake;
    }
    double fxl, fxr, upl, upr;
    double pu[2] = {ul, ur}, pv[2], pf0[2] = {f0l, f0r}, pres[2] = {rl, rr};
    double pk[2] = {kl, kr}, pair[4];
    int rigid = 0;
    /* scrub: each patch capped at its Coulomb torque (scrub.patch_scrub) */
    double isum = ivl + ivr;
    double kphl = sphi * ivl;
    double kphr = sphi * ivr;
    double kphi = sphi * isum;
    double ysum = iyl + iyr; /* > 0 for any real ground (GRIP_FLOOR_N) */
    double tl = ysum > 0.0 ? ts * iyr / ysum : 0.5 * ts;
    double tr = ts - tl;
    double torque = 0.0, scrub = 0.0;
    const double vl0 = vl, vr0 = vr;
    /* the gripping solve twice: the second time with the hubs moved by the yaw the first
     * one's scrub gives them within the step (forces.rover_step says why) */
    for (int pass = 0; pass < 2; pass++) {
        vl = vl0 - scrub * dt_i * h;
        vr = vr0 + scrub * dt_i * h;
        pv[0] = vl;
        pv[1] = vr;
        rigid = 0;
        if (ul == 0.0 && ur == 0.0) {
            if (sloped) { /* held rigidly on a slope (forces.rover_step says why) */
                double det = e * e - e2 * e2;
                fxl = (e2 * vr - e * vl) / det;
                fxr = (e2 * vl - e * vr) / det;
            } else {
                double gl = 1.0 + kl * e;
                double gr = 1.0 + kr * e;
                double cl = kl * e2;
                double cr = kr * e2;
                double bl = -kl * vl;
                double br = -kr * vr;
                double det = gl * gr - cl * cr;
                fxl = (bl * gr - cl * br) / det;
                fxr = (br * gl - cr * bl) / det;
            }
            double nl = ((-fmax <= f0l && f0l <= fmax) ? f0l : (f0l > 0 ? fmax : -fmax)) - fxl;
            double nr = ((-fmax <= f0r && f0r <= fmax) ? f0r : (f0r > 0 ? fmax : -fmax)) - fxr;
            if (-rl <= nl && nl <= rl && -rr <= nr && nr <= rr) {
                upl = upr = 0.0;
                rigid = sloped;
            } else {
                wheel_pair(pu, pv, pf0, pres, pk, &sc, pair);
                fxl = pair[0], upl = pair[1], fxr = pair[2], upr = pair[3];
            }
        } else {
            double al = (mw * ul + f0l - (ul > 0.0 ? rl : (ul < 0.0 ? -rl : 0.0))) * bb;
            double ar = (mw * ur + f0r - (ur > 0.0 ? rr : (ur < 0.0 ? -rr : 0.0))) * bb;
            double gl = 1.0 + kl * bbe;
            double gr = 1.0 + kr * bbe;
            double cl = kl * e2;
            double cr = kr * e2;
            double bl = kl * (al - vl);
            double br = kr * (ar - vr);
            double det = gl * gr - cl * cr;
            fxl = (bl * gr - cl * br) / det;
            fxr = (br * gl - cr * bl) / det;
            upl = al - bb * fxl;
            upr = ar - bb * fxr;
            double fml = f0l - c * upl;
            double fmr = f0r - c * upr;
            if (!(upl * ul > 0.0 && upr * ur > 0.0 && -fmax <= fml && fml <= fmax && -fmax <= fmr &&
                  fmr <= fmax)) {
                wheel_pair(pu, pv, pf0, pres, pk, &sc, pair);
                fxl = pair[0], upl = pair[1], fxr = pair[2], upr = pair[3];
            }
        }

        torque = (fxr - fxl) * h;
        double base = w + torque * dt_i;
        double den = 1.0 + kphi * dt_i;
        scrub = -kphi * base / den;
        double wn = base / den;
        double ql = kphl * wn, qr = kphr * wn;
        if (!(-tl <= ql && ql <= tl && -tr <= qr && qr <= tr))
            scrub = patch_scrub(w, torque, kphl, kphr, kphi, tl, tr, ts, dt_i);
        torque += scrub;
    }
    /* predicted heading change */
    double turn = w * dt + torque * turn_k;
    double end = angle + turn;
    double mid = angle + 0.5 * turn;
    double cm = cos(mid);
    double sm = sin(mid);
    double ce = cos(end);
    double se = sin(end);
    if (st->rot_ahead) {
        st->rot[3 * k] = end;
        st->rot[3 * k + 1] = ce;
        st->rot[3 * k + 2] = se;
    }
    double fx = fxl + fxr;
    double a = fx * dt_m;
    double side = (vy + a * sm) * ce - (vx + a * cm) * se;
    double kd = ky_dt_m * isum;
    double f_lat = rigid ? neg_m_dt * side / cos(0.5 * turn)
                         : neg_m_dt * side / cos(0.5 * turn) * kd / (1.0 + kd);
    double fyl = f_lat * ivl / isum;
    double fyr = f_lat - fyl;
    /* load transfer (forces.rover_step says why) */
    const double xfer = p[P_XFER];
    double ftot = fxl + fxr;
    double d = xfer * ftot > 0.0 ? xfer * ftot : -(xfer * ftot);
    if (sloped)
        d = d / sqrt(1.0 - (gax * gax + gay * gay) * p[P_INV_G2]);
    double t1 = fxl * ixl;
    double t2 = fyl * iyl;
    double t3 = fxr * ixr;
    double t4 = fyr * iyr;
    double room = d < 1.0 ? (1.0 - d) * (1.0 - d) : 0.0;
    double ax = 0.0, gxl = 0.0, gyl = 0.0, gxr = 0.0, gyr = 0.0;
    if (xfer != 0.0 && (t1 * t1 + t2 * t2 > room || t3 * t3 + t4 * t4 > room)) {
        double cs = sloped ? sqrt(1.0 - (gax * gax + gay * gay) * p[P_INV_G2]) : 1.0;
        ax = xfer / cs;
        double aa = ax > 0.0 ? ax : -ax;
        double gsum = 1.0 / ixl + 1.0 / ixr;
        double lim;
        if (ftot * ax > 0.0)
            lim = gsum / (1.0 + aa * gsum);
        else if (aa * gsum < 1.0)
            lim = gsum / (1.0 - aa * gsum);
        else
            lim = ftot > 0.0 ? ftot : -ftot;
        if (ftot > lim)
            ftot = lim;
        else if (ftot < -lim)
            ftot = -lim;
        double k = 1.0 - ax * ftot;
        if (k > p[P_KMAX])
            k = p[P_KMAX];
        else if (k < LOAD_FLOOR)
            k = LOAD_FLOOR;
        double ik = 1.0 / k;
        gxl = ixl;
        gyl = iyl;
        gxr = ixr;
        gyr = iyr;
        ixl = ixl * ik;
        iyl = iyl * ik;
        ixr = ixr * ik;
        iyr = iyr * ik;
        t1 = fxl * ixl;
        t2 = fyl * iyl;
        t3 = fxr * ixr;
        t4 = fyr * iyr;
    }
    /* friction ellipse */
    int sat_l = t1 * t1 + t2 * t2 > 1.0;
    int sat_r = t3 * t3 + t4 * t4 > 1.0;
    if (sat_l || sat_r) { /* forces.rover_step says why each part */
        double side0 = vy * co - vx * si;
        double cancel = neg_m_dt * side / cos(0.5 * turn);
        SlideIn in = {ul, vl, f0l, rl, ivl, ixl, iyl, ur, vr, f0r, rr, ivr, ixr, iyr,
                      kx, p[P_KY], ky_dt_m, cancel, &sc};
        const double grip[6] = {fxl, fyl, upl, fxr, fyr, upr};
        double o[6];
        /* the predictor: the tyre law at the step's start */
        const double start[5] = {vl, ivl, vr, ivr, side0};
        slide_pair(&in, sat_l, sat_r, grip, start, o);
        fx = o[0] + o[3];
        torque = (o[3] - o[0]) * h;
        torque += patch_scrub(w, torque, kphl, kphr, kphi, tl, tr, ts, dt_i);
        f_lat = o[1] + o[4];
        if (ax != 0.0) { /* the load the sliding tyres' own drive force leaves */
            double k = 1.0 - ax * fx;
            if (k > p[P_KMAX])
                k = p[P_KMAX];
            else if (k < LOAD_FLOOR)
                k = LOAD_FLOOR;
            double ik = 1.0 / k;
            in.ixl = gxl * ik;
            in.iyl = gyl * ik;
            in.ixr = gxr * ik;
            in.iyr = gyr * ik;
        }
        /* the sliding tyres' slip at the half step (sliding.mid_step) */
        double hub[5];
        mid_step(vx, vy, w, angle, fx * cm - f_lat * sm, fx * sm + f_lat * cm, torque, dt, dt_m,
                 dt_i, turn_k, h, hub);
        slide_pair(&in, sat_l, sat_r, grip, hub, o);
        fxl = o[0], fyl = o[1], upl = o[2], fxr = o[3], fyr = o[4], upr = o[5];
        fx = fxl + fxr;
        torque = (fxr - fxl) * h;
        torque += patch_scrub(w, torque, kphl, kphr, kphi, tl, tr, ts, dt_i);
        f_lat = fyl + fyr;
    }
    double fwx = fx * cm - f_lat * sm;
    double fwy = fx * sm + f_lat * cm;
    if (sloped) {
        fwx = fwx + p[P_MASS] * gax;
        fwy = fwy + p[P_MASS] * gay;
    }
    out[0] = fwx;
    out[1] = fwy;
    out[2] = torque;
    *rim_l = upl;
    *rim_r = upr;
}

/* ---- two rovers at once: rover_forces' usual path in lockstep --------------------------
 * Why: one rover's step is a chain of dependent operations (libm's sin and cos, divisions,
 * comparisons on their results) too long for the CPU to overlap with the next rover's; two
 * rovers' chains side by side give it independent work at every point. Each lane is
 * rover_forces' own expressions in its order (GCC may put the two lanes in one SSE2
 * register: the same IEEE operations, so the same doubles). Only the usual path: no slope,
 * no holding brake, rims turning, both tyres gripping in both passes without the scrub
 * cap, no load transfer beyond its room, no tyre sliding. At the first sign of anything
 * else nothing has been written and it returns 1: the caller calls rover_forces for each
 * rover; 0: rover k's force and torque in out[0..2], rover k + 1's in out[3..5], both
 * rovers' rims advanced. */
#define LANES _Pragma("GCC unroll 2") for (int j = 0; j < 2; j++)
static int rover_pair(Stepper *st, Py_ssize_t k, double out[6])
{
    const double dt = st->dt;
    const double vmin = SLIP_SPEED_MIN, ivmin = 1.0 / SLIP_SPEED_MIN;
    const Py_ssize_t *go = st->ground_off;
    const double *p[2];
    double *rim_l[2], *rim_r[2];
    double ixl[2], iyl[2], rl[2], ixr[2], iyr[2], rr[2], ts[2];
    double angle[2], vx[2], vy[2], w[2], co[2], si[2];
    LANES {
        const Py_ssize_t r = k + j;
        p[j] = st->plan + r * PLAN_WIDTH;
        const double *g = st->ground + r * st->ground_k;
        if (g[go[7]] != 0.0 || g[go[8]] != 0.0 || p[j][P_BRAKE] != 0.0)
            return 1; /* on a slope, or a holding brake */
        const double *state = st->state + (st->offsets ? st->offsets[r] : 6 * r);
        rim_l[j] = st->rims + r * st->rim_k;
        rim_r[j] = rim_l[j] + st->rim_side;
        ixl[j] = g[go[0]], iyl[j] = g[go[1]];
        rl[j] = g[go[2]];
        ixr[j] = g[go[3]], iyr[j] = g[go[4]];
        rr[j] = g[go[5]];
        ts[j] = g[go[6]];
        angle[j] = state[2], vx[j] = state[3], vy[j] = state[4], w[j] = state[5];
    }
    LANES {
        if (st->rot != NULL && same_bits(st->rot[3 * (k + j)], angle[j])) {
            co[j] = st->rot[3 * (k + j) + 1];
            si[j] = st->rot[3 * (k + j) + 2];
        } else {
            co[j] = cos(angle[j]);
            si[j] = sin(angle[j]);
        }
    }
    double ul[2], ur[2], vl0[2], vr0[2], ivl[2], ivr[2], kl[2], kr[2], f0l[2], f0r[2];
    double isum[2], kphl[2], kphr[2], kphi[2], tl[2], tr[2];
    LANES {
        const double *q = p[j];
        const double h = q[P_H], kx = q[P_KX], kp = q[P_KP], sphi = q[P_SPHI];
        double v_fwd = vx[j] * co[j] + vy[j] * si[j];
        double wh = w[j] * h;
        ul[j] = *rim_l[j], ur[j] = *rim_r[j];
        if (ul[j] == 0.0 && ur[j] == 0.0)
            return 1; /* rims at rest */
        double vl = v_fwd - wh;
        double vr = v_fwd + wh;
        vl0[j] = vl, vr0[j] = vr;
        ivl[j] = vl > vmin ? 1.0 / vl : (vl < -vmin ? -1.0 / vl : ivmin);
        ivr[j] = vr > vmin ? 1.0 / vr : (vr < -vmin ? -1.0 / vr : ivmin);
        kl[j] = kx * ivl[j];
        kr[j] = kx * ivr[j];
        f0l[j] = kp * st->drives[k + j] - q[P_C_EXP] * ul[j];
        f0r[j] = kp * st->drives[st->n + k + j] - q[P_C_EXP] * ur[j];
        isum[j] = ivl[j] + ivr[j];
        kphl[j] = sphi * ivl[j];
        kphr[j] = sphi * ivr[j];
        kphi[j] = sphi * isum[j];
        double ysum = iyl[j] + iyr[j];
        tl[j] = ysum > 0.0 ? ts[j] * iyr[j] / ysum : 0.5 * ts[j];
        tr[j] = ts[j] - tl[j];
    }
    double fxl[2], fxr[2], upl[2], upr[2], vl[2], vr[2];
    double torque[2] = {0.0, 0.0}, scrub[2] = {0.0, 0.0};
    for (int pass = 0; pass < 2; pass++) {
        LANES {
            const double *q = p[j];
            const double c = q[P_C], fmax = q[P_FMAX], mw = q[P_MW], bb = q[P_BB];
            const double bbe = q[P_BBE], e2 = q[P_E2], h = q[P_H], dt_i = q[P_DT_I];
            vl[j] = vl0[j] - scrub[j] * dt_i * h;
            vr[j] = vr0[j] + scrub[j] * dt_i * h;
            const double u_l = ul[j], u_r = ur[j], r_l = rl[j], r_r = rr[j];
            double al = (mw * u_l + f0l[j] - (u_l > 0.0 ? r_l : (u_l < 0.0 ? -r_l : 0.0))) * bb;
            double ar = (mw * u_r + f0r[j] - (u_r > 0.0 ? r_r : (u_r < 0.0 ? -r_r : 0.0))) * bb;
            double gl = 1.0 + kl[j] * bbe;
            double gr = 1.0 + kr[j] * bbe;
            double cl = kl[j] * e2;
            double cr = kr[j] * e2;
            double bl = kl[j] * (al - vl[j]);
            double br = kr[j] * (ar - vr[j]);
            double det = gl * gr - cl * cr;
            fxl[j] = (bl * gr - cl * br) / det;
            fxr[j] = (br * gl - cr * bl) / det;
            upl[j] = al - bb * fxl[j];
            upr[j] = ar - bb * fxr[j];
            double fml = f0l[j] - c * upl[j];
            double fmr = f0r[j] - c * upr[j];
            if (!(upl[j] * u_l > 0.0 && upr[j] * u_r > 0.0 && -fmax <= fml && fml <= fmax &&
                  -fmax <= fmr && fmr <= fmax))
                return 1; /* a tyre not gripping (wheel_pair) */
            double t = (fxr[j] - fxl[j]) * h;
            double base = w[j] + t * dt_i;
            double den = 1.0 + kphi[j] * dt_i;
            double s = -kphi[j] * base / den;
            double wn = base / den;
            double ql = kphl[j] * wn, qr = kphr[j] * wn;
            if (!(-tl[j] <= ql && ql <= tl[j] && -tr[j] <= qr && qr <= tr[j]))
                return 1; /* the scrub capped (patch_scrub) */
            scrub[j] = s;
            torque[j] = t + s;
        }
    }
    double turn[2], cm[2], sm[2], ce[2], se[2], ch[2];
    LANES {
        turn[j] = w[j] * dt + torque[j] * p[j][P_TURN_K];
        double end = angle[j] + turn[j];
        double mid = angle[j] + 0.5 * turn[j];
        cm[j] = cos(mid);
        sm[j] = sin(mid);
        ce[j] = cos(end);
        se[j] = sin(end);
        ch[j] = cos(0.5 * turn[j]);
        if (st->rot_ahead) { /* a true triple even if rover_forces takes over below */
            st->rot[3 * (k + j)] = end;
            st->rot[3 * (k + j) + 1] = ce[j];
            st->rot[3 * (k + j) + 2] = se[j];
        }
    }
    double f[6];
    LANES {
        const double *q = p[j];
        double fx = fxl[j] + fxr[j];
        double a = fx * q[P_DT_M];
        double side = (vy[j] + a * sm[j]) * ce[j] - (vx[j] + a * cm[j]) * se[j];
        double kd = q[P_KY_DT_M] * isum[j];
        double f_lat = q[P_NEG_M_DT] * side / ch[j] * kd / (1.0 + kd);
        double fyl = f_lat * ivl[j] / isum[j];
        double fyr = f_lat - fyl;
        const double xfer = q[P_XFER];
        double ftot = fxl[j] + fxr[j];
        double d = xfer * ftot > 0.0 ? xfer * ftot : -(xfer * ftot);
        double t1 = fxl[j] * ixl[j];
        double t2 = fyl * iyl[j];
        double t3 = fxr[j] * ixr[j];
        double t4 = fyr * iyr[j];
        double room = d < 1.0 ? (1.0 - d) * (1.0 - d) : 0.0;
        if (xfer != 0.0 && (t1 * t1 + t2 * t2 > room || t3 * t3 + t4 * t4 > room))
            return 1; /* the load transfer's limit */
        if (t1 * t1 + t2 * t2 > 1.0 || t3 * t3 + t4 * t4 > 1.0)
            return 1; /* a tyre sliding */
        f[3 * j] = fx * cm[j] - f_lat * sm[j];
        f[3 * j + 1] = fx * sm[j] + f_lat * cm[j];
        f[3 * j + 2] = torque[j];
    }
    LANES {
        out[3 * j] = f[3 * j];
        out[3 * j + 1] = f[3 * j + 1];
        out[3 * j + 2] = f[3 * j + 2];
        *rim_l[j] = upl[j];
        *rim_r[j] = upr[j];
    }
    return 0;
}
#undef LANES

/* ---- the step's parts ------------------------------------------------------------------ */
/* bodyio.substeps: Chipmunk steps in this physics step, so that no rover tunnels */
static int substeps(double top2, double sub_speed)
{
    double sub2 = sub_speed * sub_speed;
    if (!(top2 > sub2))
        return 1;
    return (int)ceil(sqrt(top2) / sub_speed);
}

/* Rovers k0 (even) to k1's force and torque for this step (rims advanced), into the (n, 3)
 * out; two by two where they can (rover_pair), the pairs (0, 1), (2, 3), ... whatever the
 * range, so a split at even indices pairs every rover as the whole range does. */
static void rovers_forces_range(Stepper *st, double *out, Py_ssize_t k0, Py_ssize_t k1)
{
    for (Py_ssize_t k = k0; k < k1; k += 2)
        if (k + 1 >= k1 || rover_pair(st, k, out + 3 * k) != 0) {
            rover_forces(st, k, out + 3 * k);
            if (k + 1 < k1)
                rover_forces(st, k + 1, out + 3 * k + 3);
        }
}

/* Every rover's force and torque for this step (rims advanced), into the (n, 3) out. */
static void rovers_forces(Stepper *st, double *out)
{
    rovers_forces_range(st, out, 0, st->n);
}

static void apply_all(Stepper *st)
{
    for (Py_ssize_t k = 0; k < st->n; k += 2) {
        double f[6];
        const int both = k + 1 < st->n && rover_pair(st, k, f) == 0;
        for (Py_ssize_t i = k; i < k + 2 && i < st->n; i++) {
            double *fi = f + 3 * (i - k);
            if (!both)
                rover_forces(st, i, fi);
            cpVect force = {fi[0], fi[1]};
            st->set_force(st->bodies[i], force);
            st->set_torque(st->bodies[i], fi[2]);
        }
    }
}

/* Read every rover's state; the first rover (by index) too fast or outside, or -1. */
static Py_ssize_t read_check(Stepper *st)
{
    Py_ssize_t bad = -1;
    const double max2 = st->max2, extent = st->extent;
    double top2 = 0.0;
    for (Py_ssize_t k = 0; k < st->n; k++) {
        void *b = st->bodies[k];
        double *s = st->state + st->offsets[k];
        cpVect p, v;
        if (st->direct) {
            const double *bv = body_at(b, BODY_V);
            p = body_position(b);
            v.x = bv[0];
            v.y = bv[1];
            s[2] = *body_at(b, BODY_A);
            s[5] = *body_at(b, BODY_W);
        } else {
            p = st->get_position(b);
            v = st->get_velocity(b);
            s[2] = st->get_angle(b);
            s[5] = st->get_angular_velocity(b);
        }
        s[0] = p.x;
        s[1] = p.y;
        if (st->rot != NULL) {
            double *c = st->rot + 3 * k;
            c[0] = s[2];
            if (st->direct) { /* cpBodyGetRotation: the transform's a and b */
                c[1] = body_at(b, BODY_T)[0];
                c[2] = body_at(b, BODY_T)[1];
            } else {
                cpVect r = st->get_rotation(b);
                c[1] = r.x;
                c[2] = r.y;
            }
        }
        s[3] = v.x;
        s[4] = v.y;
        double v2 = v.x * v.x + v.y * v.y;
        if (v2 > top2)
            top2 = v2;
        if (bad < 0 && !(v2 <= max2 && -extent <= p.x && p.x <= extent &&
                         -extent <= p.y && p.y <= extent))
            bad = k;
    }
    if (bad < 0)
        st->top2 = top2;
    return bad;
}

/* ---- the second-order pose update ------------------------------------------------------
 * Chipmunk moves a body by the velocity it has at the start of a step (cpBodyUpdatePosition
 * before cpBodyUpdateVelocity), so under an acceleration a the pose lags by a t dt / 2: a
 * first-order error (a 3 s spin-up from rest on mu 0.1: 0.032 rad of heading at 100 Hz).
 * After each Chipmunk step the body is moved on by half the step's change of velocity times
 * the step: p += (v1 - v0) h / 2, a += (w1 - w0) h / 2, so the step as a whole is the
 * trapezoid p += (v0 + v1) h / 2. The velocities are untouched (no energy is added or
 * taken); a contact impulse's change of velocity moves the body by half of it times h too,
 * as the trapezoid would. Chipmunk recomputes the body's rotation from the new angle (the
 * cache below stays valid). bodyio.trapezoid is the pure path's copy: the same operations in
 * the same order. */
static void velocities_before(Stepper *st)
{
    for (Py_ssize_t k = 0; k < st->n; k++) {
        void *b = st->bodies[k];
        double *w0 = st->v0 + 3 * k;
        if (st->direct) {
            const double *bv = body_at(b, BODY_V);
            w0[0] = bv[0];
            w0[1] = bv[1];
            w0[2] = *body_at(b, BODY_W);
            continue;
        }
        cpVect v = st->get_velocity(b);
        w0[0] = v.x;
        w0[1] = v.y;
        w0[2] = st->get_angular_velocity(b);
    }
}

static void second_order(Stepper *st, double half)
{
    for (Py_ssize_t k = 0; k < st->n; k++) {
        void *b = st->bodies[k];
        const double *w0 = st->v0 + 3 * k;
        if (st->direct) {
            const double *bv = body_at(b, BODY_V), *t = body_at(b, BODY_T);
            const double *cog = body_at(b, BODY_COG);
            cpVect p = body_position(b);
            double a = *body_at(b, BODY_A);
            double w = *body_at(b, BODY_W);
            cpVect q = {p.x + (bv[0] - w0[0]) * half, p.y + (bv[1] - w0[1]) * half};
            /* cpBodySetPosition(b, q) but its transform, which cpBodySetAngle sets again
             * from the same p at once: body->p = cpvadd(cpTransformVect(transform, cog), q) */
            double *bp = (double *)((char *)b + BODY_P);
            bp[0] = (t[0] * cog[0] + t[2] * cog[1]) + q.x;
            bp[1] = (t[1] * cog[0] + t[3] * cog[1]) + q.y;
            st->set_angle(b, a + (w - w0[2]) * half);
            continue;
        }
        cpVect p = st->get_position(b);
        cpVect v = st->get_velocity(b);
        double a = st->get_angle(b);
        double w = st->get_angular_velocity(b);
        cpVect q = {p.x + (v.x - w0[0]) * half, p.y + (v.y - w0[1]) * half};
        st->set_position(b, q);
        st->set_angle(b, a + (w - w0[2]) * half);
    }
}

/* One physics step's Chipmunk steps (bodyio.BodyIO.step): each a trapezoid. */
static void space_steps(Stepper *st)
{
    int n = substeps(st->top2, st->sub_speed);
    double h = st->dt / (double)n;
    double half = 0.5 * h;
    for (int i = 0; i < n && !PyErr_Occurred(); i++) {
        velocities_before(st);
        st->space_step(st->space, h);
        if (!PyErr_Occurred())
            second_order(st, half);
    }
}

static PyObject *Stepper_advance(Stepper *st, PyObject *Py_UNUSED(ignored))
{
    apply_all(st);
    space_steps(st);
    if (PyErr_Occurred()) /* a collision callback raised (cffi reports, never sets) */
        return NULL;
    return PyLong_FromSsize_t(read_check(st));
}

/* Up to ``count`` whole steps in one call, each as Stepper_advance takes it: (steps run,
 * the first bad rover's index after the last of them or -1). ``batch_i`` is the step under
 * way (a collision callback reads it to know its step's time, and may end the batch after
 * that step with stop_batch). The caller locks the space. */
static PyObject *Stepper_advance_many(Stepper *st, PyObject *arg)
{
    Py_ssize_t count = PyLong_AsSsize_t(arg);
    if (count == -1 && PyErr_Occurred())
        return NULL;
    Py_ssize_t done = 0;
    st->stop = 0;
    while (done < count && !st->stop) {
        st->batch_i = done;
        apply_all(st);
        space_steps(st);
        if (PyErr_Occurred())
            return NULL;
        done++;
        Py_ssize_t bad = read_check(st);
        if (bad >= 0)
            return Py_BuildValue("(nn)", done, bad);
    }
    return Py_BuildValue("(nn)", done, (Py_ssize_t)-1);
}

static PyObject *Stepper_stop_batch(Stepper *st, PyObject *Py_UNUSED(ignored))
{
    st->stop = 1;
    Py_RETURN_NONE;
}

static PyObject *Stepper_apply(Stepper *st, PyObject *Py_UNUSED(ignored))
{
    apply_all(st);
    Py_RETURN_NONE;
}

static PyObject *Stepper_before(Stepper *st, PyObject *Py_UNUSED(ignored))
{
    velocities_before(st);
    Py_RETURN_NONE;
}

static PyObject *Stepper_after(Stepper *st, PyObject *arg)
{
    double h = PyFloat_AsDouble(arg);
    if (h == -1.0 && PyErr_Occurred())
        return NULL;
    second_order(st, 0.5 * h);
    Py_RETURN_NONE;
}

static PyObject *Stepper_read_check(Stepper *st, PyObject *Py_UNUSED(ignored))
{
    return PyLong_FromSsize_t(read_check(st));
}

static PyObject *Stepper_kinematics(Stepper *st, PyObject *arg)
{
    Py_ssize_t k = PyLong_AsSsize_t(arg);
    if (k == -1 && PyErr_Occurred())
        return NULL;
    if (k < 0 || k >= st->n) {
        PyErr_SetString(PyExc_IndexError, "rover index out of range");
        return NULL;
    }
    const double *s = st->state + st->offsets[k];
    PyObject *out = PyList_New(6);
    if (out == NULL)
        return NULL;
    for (int i = 0; i < 6; i++) {
        PyObject *f = PyFloat_FromDouble(s[i]);
        if (f == NULL) {
            Py_DECREF(out);
            return NULL;
        }
        PyList_SET_ITEM(out, i, f);
    }
    return out;
}

static PyObject *Stepper_rim_speeds(Stepper *st, PyObject *arg)
{
    Py_ssize_t k = PyLong_AsSsize_t(arg);
    if (k == -1 && PyErr_Occurred())
        return NULL;
    if (k < 0 || k >= st->n) {
        PyErr_SetString(PyExc_IndexError, "rover index out of range");
        return NULL;
    }
    const double *r = st->rims + k * st->rim_k;
    return Py_BuildValue("(dd)", r[0], r[st->rim_side]);
}

/* ---- construction ---------------------------------------------------------------------- */
static void Stepper_dealloc(Stepper *st)
{
    for (int i = 0; i < st->n_views; i++)
        PyBuffer_Release(&st->views[i]);
    PyMem_Free(st->rot);
    PyMem_Free(st->v0);
    Py_TYPE(st)->tp_free((PyObject *)st);
}

/* Take a writable, C-contiguous buffer of at least ``need`` items of ``itemsize`` bytes. */
static void *take(Stepper *st, PyObject *obj, Py_ssize_t itemsize, Py_ssize_t need,
                  const char *what)
{
    Py_buffer *view = &st->views[st->n_views];
    if (PyObject_GetBuffer(obj, view, PyBUF_WRITABLE | PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0)
        return NULL;
    st->n_views++;
    if (view->itemsize != itemsize || view->len < need * itemsize) {
        PyErr_Format(PyExc_ValueError, "%s: need %zd items of %zd bytes", what, need, itemsize);
        return NULL;
    }
    return view->buf;
}

static int Stepper_init(Stepper *st, PyObject *args, PyObject *kwds)
{
    static char *kwlist[] = {"space",  "functions", "bodies",   "offsets", "plan",
                             "drives", "rims",      "rim_strides", "ground", "ground_layout",
                             "state",  "dt",        "max2",     "extent",  "sub_speed",
                             "direct", NULL};
    unsigned long long space;
    PyObject *fns, *bodies, *offsets, *plan, *drives, *rims, *ground, *state;
    Py_ssize_t rim_k, rim_side, ground_k;
    Py_ssize_t go[GROUND_TERMS];
    double dt, max2, extent, sub_speed = INFINITY;
    int direct = 0;
    if (st->n_views) {
        PyErr_SetString(PyExc_RuntimeError, "Stepper is initialised once");
        return -1;
    }
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "KO!OOOOO(nn)O(n(nnnnnnnnn))Oddd|dp", kwlist, &space,
                                     &PyTuple_Type, &fns, &bodies, &offsets, &plan, &drives,
                                     &rims, &rim_k, &rim_side, &ground, &ground_k, &go[0],
                                     &go[1], &go[2], &go[3], &go[4], &go[5], &go[6], &go[7], &go[8], &state, &dt,
                                     &max2, &extent, &sub_speed, &direct))
        return -1;
    const Py_ssize_t n_fns = PyTuple_GET_SIZE(fns);
    if (n_fns != 9 && n_fns != 10) {
        PyErr_SetString(PyExc_ValueError, "functions: nine or ten addresses");
        return -1;
    }
    void *fp[10] = {NULL};
    for (int i = 0; i < n_fns; i++) {
        fp[i] = PyLong_AsVoidPtr(PyTuple_GET_ITEM(fns, i));
        if (fp[i] == NULL) {
            if (!PyErr_Occurred())
                PyErr_SetString(PyExc_ValueError, "functions: a null address");
            return -1;
        }
    }
    st->space = (void *)(uintptr_t)space;
    st->get_position = (get_vect_fn)fp[0];
    st->get_angle = (get_double_fn)fp[1];
    st->get_velocity = (get_vect_fn)fp[2];
    st->get_angular_velocity = (get_double_fn)fp[3];
    st->set_force = (set_vect_fn)fp[4];
    st->set_torque = (set_double_fn)fp[5];
    st->space_step = (space_step_fn)fp[6];
    st->set_position = (set_vect_fn)fp[7];
    st->set_angle = (set_double_fn)fp[8];
    st->get_rotation = (get_vect_fn)fp[9];
    Py_ssize_t nb;
    {
        Py_buffer *view = &st->views[st->n_views];
        if (PyObject_GetBuffer(bodies, view, PyBUF_C_CONTIGUOUS | PyBUF_FORMAT) < 0)
            return -1;
        st->n_views++;
        if (view->itemsize != (Py_ssize_t)sizeof(void *)) {
            PyErr_SetString(PyExc_ValueError, "bodies: pointer-sized items");
            return -1;
        }
        nb = view->len / view->itemsize;
        st->bodies = (void **)view->buf;
    }
    st->n = nb;
    if (!(st->offsets = take(st, offsets, 8, nb, "offsets")) ||
        !(st->plan = take(st, plan, 8, nb * PLAN_WIDTH, "plan")) ||
        !(st->drives = take(st, drives, 8, 2 * nb, "drives")) ||
        !(st->rims = take(st, rims, 8, 2 * nb, "rims")))
        return -1;
    Py_ssize_t ground_need = 0, rim_need = 0;
    for (int t = 0; t < GROUND_TERMS; t++)
        if (go[t] + 1 > ground_need)
            ground_need = go[t] + 1;
    if (nb) {
        ground_need += (nb - 1) * ground_k;
        rim_need = (nb - 1) * rim_k + rim_side + 1;
    }
    Py_buffer *rv = &st->views[st->n_views - 1];
    if (rim_k < 0 || rim_side < 0 || rv->len < rim_need * 8) {
        PyErr_SetString(PyExc_ValueError, "rims: strides out of range");
        return -1;
    }
    if (!(st->ground = take(st, ground, 8, ground_need, "ground")))
        return -1;
    Py_ssize_t state_len;
    if (!(st->state = take(st, state, 8, 0, "state")))
        return -1;
    state_len = st->views[st->n_views - 1].len / 8;
    for (Py_ssize_t k = 0; k < nb; k++)
        if (st->offsets[k] < 0 || st->offsets[k] + 6 > state_len) {
            PyErr_SetString(PyExc_ValueError, "offsets: beyond the state");
            return -1;
        }
    st->rim_k = rim_k;
    st->rim_side = rim_side;
    st->ground_k = ground_k;
    for (int t = 0; t < GROUND_TERMS; t++)
        st->ground_off[t] = go[t];
    st->dt = dt;
    st->max2 = max2;
    st->extent = extent;
    st->sub_speed = sub_speed;
    st->direct = direct;
    st->top2 = 0.0;
    st->v0 = PyMem_Malloc((nb ? 3 * nb : 1) * sizeof(double));
    if (st->v0 == NULL) {
        PyErr_NoMemory();
        return -1;
    }
    if (st->get_rotation != NULL) {
        st->rot = PyMem_Malloc((nb ? 3 * nb : 1) * sizeof(double));
        if (st->rot == NULL) {
            PyErr_NoMemory();
            return -1;
        }
        for (Py_ssize_t k = 0; k < nb; k++) { /* the state given: computed as rover_forces does */
            double a = st->state[st->offsets[k] + 2];
            st->rot[3 * k] = a;
            st->rot[3 * k + 1] = cos(a);
            st->rot[3 * k + 2] = sin(a);
        }
    }
    for (Py_ssize_t k = 0; k < st->n; k++) { /* as FewRovers.__init__ */
        const double *s = st->state + st->offsets[k];
        double v2 = s[3] * s[3] + s[4] * s[4];
        if (v2 > st->top2)
            st->top2 = v2;
    }
    return 0;
}

static PyMethodDef Stepper_methods[] = {
    {"advance", (PyCFunction)Stepper_advance, METH_NOARGS,
     "Forces, body writes, cpSpaceStep, body reads and the safety check: the first bad "
     "rover's index, or -1. The caller locks the space as pymunk would."},
    {"advance_many", (PyCFunction)Stepper_advance_many, METH_O,
     "Up to n steps, each as advance: (steps run, the first bad rover's index after the "
     "last, or -1). The caller locks the space as pymunk would."},
    {"stop_batch", (PyCFunction)Stepper_stop_batch, METH_NOARGS,
     "End advance_many after the step under way."},
    {"apply", (PyCFunction)Stepper_apply, METH_NOARGS,
     "Forces and body writes only (the caller steps the space itself)."},
    {"before", (PyCFunction)Stepper_before, METH_NOARGS,
     "Keep every rover's velocity before a Chipmunk step the caller takes itself."},
    {"after", (PyCFunction)Stepper_after, METH_O,
     "After that step of h seconds: the trapezoid's correction of every rover's pose."},
    {"read_check", (PyCFunction)Stepper_read_check, METH_NOARGS,
     "Body reads and the safety check only: the first bad rover's index, or -1."},
    {"kinematics", (PyCFunction)Stepper_kinematics, METH_O,
     "Rover k's x, y, angle, vx, vy, w as a new list."},
    {"rim_speeds", (PyCFunction)Stepper_rim_speeds, METH_O,
     "Rover k's left and right rim speeds."},
    {NULL, NULL, 0, NULL},
};

static PyMemberDef Stepper_members[] = {
    {"batch_i", T_PYSSIZET, offsetof(Stepper, batch_i), READONLY,
     "advance_many: the step under way (0: the first)."},
    {NULL, 0, 0, 0, NULL},
};

static PyTypeObject StepperType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "amsa_phys.physics._step.Stepper",
    .tp_basicsize = sizeof(Stepper),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "The rovers' physics step over buffers shared with compiled.py.",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)Stepper_init,
    .tp_dealloc = (destructor)Stepper_dealloc,
    .tp_methods = Stepper_methods,
    .tp_members = Stepper_members,
};

/* ---- the module functions' array arguments ------------------------------------------
 * The format's first character without its byte-order prefix ("<", "=", "@"). */
static const char *item_format(const Py_buffer *view)
{
    const char *f = view->format ? view->format : "B";
    return (*f == '<' || *f == '=' || *f == '@') ? f + 1 : f;
}

/* Why one function: every module function below takes numpy arrays by the buffer protocol and
 * must refuse a wrong one (dtype, layout) with a ValueError naming it, releasing what it took.
 * ``kinds[i]``: 'd' a float64 array read, 'w' a float64 array written, 'i' an int64 array
 * read. Returns how many views are held: ``count`` when all are, fewer after an error (the
 * caller releases those ``held`` and returns NULL). */
static int acquire_views(PyObject *const *objs, Py_buffer *views, const char *const *names,
                         const char *kinds, int count)
{
    for (int held = 0; held < count; held++) {
        const int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT |
                          (kinds[held] == 'w' ? PyBUF_WRITABLE : 0);
        if (PyObject_GetBuffer(objs[held], &views[held], flags) < 0)
            return held;
        const char *f = item_format(&views[held]);
        const int ints = kinds[held] == 'i';
        const int ok = views[held].itemsize == 8 &&
                       (ints ? (strchr("qlQL", *f) != NULL && f[1] == 0) : strcmp(f, "d") == 0);
        if (!ok) {
            PyErr_Format(PyExc_ValueError, "%s: %s items expected", names[held],
                         ints ? "int64" : "float64");
            PyBuffer_Release(&views[held]);
            return held;
        }
    }
    return count;
}

/* ---- column_forces: the force model alone, over a batch's columns (physics/columns.py) ---
 * Why: a batched sweep integrates its rovers itself (no Space to step), and the numpy fleet's
 * masks for the rare branches cost half of a batch. This is rover_forces above (the same
 * code, so the same floats as a run made alone with the compiled step) over arrays laid out
 * as fleet.Fleet's: plan (n, PLAN_WIDTH), drives (2, n), rims (2, n, updated in place),
 * ground (9, n) in fleet._GROUND_ROWS order, state (n, 6); forces (n, 3) are written. */
static PyObject *column_forces(PyObject *Py_UNUSED(module), PyObject *args)
{
    PyObject *objs[6];
    double dt;
    if (!PyArg_ParseTuple(args, "OOOOOOd", &objs[0], &objs[1], &objs[2], &objs[3], &objs[4],
                          &objs[5], &dt))
        return NULL;
    static const char *names[6] = {"plan", "drives", "rims", "ground", "state", "forces"};
    Py_buffer views[6];
    PyObject *result = NULL;
    const int held = acquire_views(objs, views, names, "ddwddw", 6);
    if (held < 6)
        goto done;
    Py_ssize_t n = views[4].len / (6 * 8);
    const Py_ssize_t need[6] = {n * PLAN_WIDTH, 2 * n, 2 * n, GROUND_TERMS * n, 6 * n, 3 * n};
    for (int i = 0; i < 6; i++)
        if (views[i].len != need[i] * 8) {
            PyErr_Format(PyExc_ValueError, "%s: %zd floats expected for %zd rovers, got %zd",
                         names[i], need[i], n, views[i].len / 8);
            goto done;
        }
    Stepper st;
    memset(&st, 0, sizeof st);
    st.n = n;
    st.plan = views[0].buf;
    st.drives = views[1].buf;
    st.rims = views[2].buf;
    st.rim_k = 1;
    st.rim_side = n;
    st.ground = views[3].buf;
    st.ground_k = 1;
    for (int t = 0; t < GROUND_TERMS; t++)
        st.ground_off[t] = ground_rows[t] * n;
    st.state = views[4].buf;
    st.dt = dt;
    rovers_forces(&st, views[5].buf);
    result = Py_None;
    Py_INCREF(result);
done:
    for (int i = 0; i < held; i++)
        PyBuffer_Release(&views[i]);
    return result;
}

/* ---- Columns: a batch's whole physics step (physics/columns.py) -------------------------
 * Why: column_forces followed by the integration, the contact screening and the safety check
 * in numpy cost a 250-run batch of two-rover runs ~65 us a step, half of the batch; the
 * numpy part (~35 ops on 500-value columns, each a pass and an allocation) was more than the
 * forces. This does the four in one call over the same arrays, with the same operations in
 * the same order, so the same floats:
 *  1. ColumnPhysics._contacts on the state before the step: each rover's reach
 *     radius + reach_m + 2 dt |v|, a run marked (touched) when one of its rovers is faster
 *     than 0.99 of its run's resolvable speed, comes within reach of another of its rovers
 *     (the pairs) or of a static shape's box;
 *  2. rover_forces, as column_forces (forces written to the (n, 3) array, rims advanced);
 *  3. Chipmunk's update of a body without contacts (cpBodyUpdatePosition, then
 *     cpBodyUpdateVelocity with damping 1 and no gravity), as _ColumnIO.step;
 *  4. the usual-case safety check of Fleet.advance: every rover's vx^2 + vy^2 <= max2 and
 *     |x|, |y| <= extent (NaN fails); advance() returns whether all passed, and the caller
 *     finds the first violation as before. */
#define COLUMN_BUFFERS 16

typedef struct {
    PyObject_HEAD
    Stepper st; /* the force model's view of the arrays (no bodies, no Space) */
    Py_buffer views[COLUMN_BUFFERS];
    int n_views;
    double *forces;
    const double *m_inv, *i_inv, *radius, *sub, *boxes;
    const int64_t *run, *pa, *pb;
    uint8_t *touched;
    double *reach; /* scratch: each rover's reach this step, then its bound */
    Py_ssize_t *miss; /* scratch: the rovers whose new angle is not their predicted one */
    Py_ssize_t n_pairs, n_boxes, n_runs;
    double reach_m, max2, extent;
    int threads; /* parts the move takes (workers.h): 1, or the workers' pool below */
    Pool *pool;  /* started at the first threaded step */
} Columns;

/* np.maximum: NaN wins, else the larger (the first of two equal ones) */
static inline double np_maximum(double a, double b)
{
    return (a >= b || a != a) ? a : b;
}

/* The screening's libm calls, mostly skipped: hypot(x, y) lies between max(|x|, |y|) and
 * |x| + |y|, so a rover whose |vx| + |vy| is below its limit is not fast, and a pair (or a
 * rover and a box) farther apart in x or in y than an upper bound of their reaches is not
 * near, without a hypot. SCREEN_SLACK, relative, is far above the few roundings between
 * the bounds and the exact values; every case within it, and NaN and infinity (which fail
 * the bounds' comparisons), takes the exact test below, the numpy path's: the same runs are
 * marked. Why: two hypot calls a rover and step were ~10 % of a batch's column step. */
#define SCREEN_SLACK 1e-9

/* Rover k's reach this step, as ColumnPhysics._near computes it: radius + reach_m +
 * 2 dt hypot(vx, vy); computed once a step, when a test needs it (c->reach[k] < 0: not
 * yet; a NaN reach stays NaN). */
static double screen_reach(Columns *c, Py_ssize_t k)
{
    if (c->reach[k] < 0.0) {
        const double *r = c->st.state + 6 * k;
        c->reach[k] = c->radius[k] + c->reach_m + 2.0 * c->st.dt * hypot(r[3], r[4]);
    }
    return c->reach[k];
}

static void Columns_screen(Columns *c)
{
    const Stepper *st = &c->st;
    const double *s = st->state;
    const double dt = st->dt;
    double *hi = c->reach + st->n; /* each rover's reach bound, |vx| + |vy| for the speed */
    for (Py_ssize_t k = 0; k < st->n; k++) {
        const double *r = s + 6 * k;
        const double sum = fabs(r[3]) + fabs(r[4]);
        c->reach[k] = -1.0;
        hi[k] = (c->radius[k] + c->reach_m + 2.0 * dt * sum) * (1.0 + SCREEN_SLACK);
        if (sum < 0.99 * c->sub[k] * (1.0 - SCREEN_SLACK))
            continue; /* slower than hypot's test could find fast */
        double speed = hypot(r[3], r[4]);
        c->reach[k] = c->radius[k] + c->reach_m + 2.0 * dt * speed;
        if (speed > 0.99 * c->sub[k])
            c->touched[c->run[k]] = 1;
    }
    for (Py_ssize_t p = 0; p < c->n_pairs; p++) {
        const Py_ssize_t ia = c->pa[p], ib = c->pb[p];
        const double *a = s + 6 * ia, *b = s + 6 * ib;
        const double dx = a[0] - b[0], dy = a[1] - b[1];
        const double bound = (hi[ia] + hi[ib]) * (1.0 + SCREEN_SLACK);
        if (fabs(dx) > bound || fabs(dy) > bound)
            continue; /* farther apart than both reaches: hypot(dx, dy) >= max(|dx|, |dy|) */
        double gap = hypot(dx, dy);
        if (gap < screen_reach(c, ia) + screen_reach(c, ib))
            c->touched[c->run[ia]] = 1;
    }
    if (c->n_boxes == 0)
        return;
    for (Py_ssize_t k = 0; k < st->n; k++) {
        const double x = s[6 * k], y = s[6 * k + 1];
        const double bound = hi[k] * (1.0 + SCREEN_SLACK);
        for (Py_ssize_t j = 0; j < c->n_boxes; j++) {
            const double *b = c->boxes + 4 * j; /* left, bottom, right, top */
            double dx = np_maximum(np_maximum(b[0] - x, 0.0), x - b[2]);
            double dy = np_maximum(np_maximum(b[1] - y, 0.0), y - b[3]);
            if (dx > bound || dy > bound)
                continue;
            if (hypot(dx, dy) < screen_reach(c, k)) {
                c->touched[c->run[k]] = 1;
                break;
            }
        }
    }
}

/* The step after the screening for rovers k0 (even) to k1: their forces, their integration
 * and the check; whether every one of them passed. A rover's forces and integration read
 * and write only its own rows, so ranges can run at once (Columns_move_part). */
static int Columns_move_range(Columns *c, Py_ssize_t k0, Py_ssize_t k1)
{
    Stepper *st = &c->st;
    const double dt = st->dt;
    const double half = 0.5 * dt;
    double *s = st->state;
    int ok = 1;
    Py_ssize_t *miss = c->miss + k0, m = 0;
    rovers_forces_range(st, c->forces, k0, k1); /* a rover's forces read only its own row */
    for (Py_ssize_t k = k0; k < k1; k++) {
        const double *f = c->forces + 3 * k;
        double *r = s + 6 * k;
        const double vx = r[3], vy = r[4], w = r[5];
        r[0] = r[0] + (r[3] + 0.0) * dt;
        r[1] = r[1] + (r[4] + 0.0) * dt;
        r[2] = r[2] + (r[5] + 0.0) * dt;
        r[3] = r[3] + (0.0 + f[0] * c->m_inv[k]) * dt;
        r[4] = r[4] + (0.0 + f[1] * c->m_inv[k]) * dt;
        r[5] = r[5] + f[2] * c->i_inv[k] * dt;
        r[0] = r[0] + (r[3] - vx) * half; /* second_order */
        r[1] = r[1] + (r[4] - vy) * half;
        r[2] = r[2] + (r[5] - w) * half;
        double v2 = r[3] * r[3] + r[4] * r[4];
        if (!(v2 <= c->max2 && fabs(r[0]) <= c->extent && fabs(r[1]) <= c->extent))
            ok = 0;
        /* the angle's cos and sin for the next step's forces: the forces' end angle's where
         * the integration landed on it bit for bit (most steps), listed without a branch */
        miss[m] = k;
        m += !same_bits(st->rot[3 * k], r[2]);
    }
    for (Py_ssize_t i = 0; i < m; i++) { /* the others: computed as rover_forces would */
        const Py_ssize_t k = miss[i];
        const double a = s[6 * k + 2];
        st->rot[3 * k] = a;
        st->rot[3 * k + 1] = cos(a);
        st->rot[3 * k + 2] = sin(a);
    }
    return ok;
}

/* Chunk ``chunk`` of ``chunks`` of the move (a pool_job): the rovers between two even
 * boundaries, in proportion. */
static int Columns_move_part(void *ctx, int chunk, int chunks)
{
    Columns *c = (Columns *)ctx;
    const Py_ssize_t n = c->st.n;
    Py_ssize_t k0 = (Py_ssize_t)((double)n * chunk / chunks) & ~(Py_ssize_t)1;
    Py_ssize_t k1 =
        chunk + 1 == chunks ? n : (Py_ssize_t)((double)n * (chunk + 1) / chunks) & ~(Py_ssize_t)1;
    return k0 < k1 ? Columns_move_range(c, k0, k1) : 1;
}

/* A step's chunks: four a thread (a helper late for a step leaves the caller no long wait),
 * each of at least COLUMN_CHUNK_MIN rovers (~7 us of work: below that a helper's wake-up
 * costs more than it shares, and a batch of fewer rovers runs on the calling thread alone). */
#define COLUMN_CHUNK_MIN 64
static int column_chunks(Py_ssize_t n, int threads)
{
    Py_ssize_t most = n / COLUMN_CHUNK_MIN;
    Py_ssize_t want = 4 * (Py_ssize_t)threads;
    return (int)(most < 1 ? 1 : want < most ? want : most);
}

/* The step after the screening: every rover's forces, its integration and the check;
 * whether every rover passed. With ``threads`` above 1 (and rovers for more than one chunk)
 * the chunks are shared between this thread and the pool's helpers (workers.h); the GIL may
 * be released meanwhile (no Python API below). */
static int Columns_move(Columns *c)
{
    if (c->threads > 1 && c->pool == NULL) {
        const int chunks = column_chunks(c->st.n, c->threads);
        const int helpers = (chunks < c->threads ? chunks : c->threads) - 1;
        if (helpers > 0 && (c->pool = (Pool *)PyMem_RawMalloc(sizeof(Pool))) != NULL)
            pool_start(c->pool, helpers, Columns_move_part, c, chunks);
        else
            c->threads = 1; /* one chunk, or no memory for the pool: one thread, same floats */
    }
    if (c->pool != NULL)
        return pool_run(c->pool);
    return Columns_move_range(c, 0, c->st.n);
}

static PyObject *Columns_advance(Columns *c, PyObject *Py_UNUSED(ignored))
{
    int ok;
    Py_BEGIN_ALLOW_THREADS
    Columns_screen(c);
    ok = Columns_move(c);
    Py_END_ALLOW_THREADS
    return PyBool_FromLong(ok);
}

static void Columns_dealloc(Columns *c)
{
    if (c->pool != NULL) {
        pool_stop(c->pool);
        PyMem_RawFree(c->pool);
    }
    for (int i = 0; i < c->n_views; i++)
        PyBuffer_Release(&c->views[i]);
    PyMem_Free(c->reach);
    PyMem_Free(c->miss);
    PyMem_Free(c->st.rot);
    Py_TYPE(c)->tp_free((PyObject *)c);
}

/* A C-contiguous buffer of exactly ``need`` items of ``itemsize`` bytes (``fmt``: "d" for
 * float64, NULL for any 8-byte integer, "B" for uint8), held until dealloc. */
static void *column_buffer(Columns *c, PyObject *obj, const char *what, Py_ssize_t need,
                           Py_ssize_t itemsize, const char *fmt, int writable)
{
    Py_buffer *view = &c->views[c->n_views];
    int flags = PyBUF_C_CONTIGUOUS | PyBUF_FORMAT | (writable ? PyBUF_WRITABLE : 0);
    if (PyObject_GetBuffer(obj, view, flags) < 0)
        return NULL;
    c->n_views++;
    const char *f = item_format(view);
    int kind_ok = fmt ? strcmp(f, fmt) == 0 : (strchr("qlQL", *f) != NULL && f[1] == 0);
    if (view->itemsize != itemsize || !kind_ok || view->len != need * itemsize) {
        PyErr_Format(PyExc_ValueError, "%s: %zd items of %zd bytes (%s) expected", what, need,
                     itemsize, fmt ? fmt : "int64");
        return NULL;
    }
    return view->buf;
}

static int Columns_init(Columns *c, PyObject *args, PyObject *kwds)
{
    static char *kwlist[] = {"plan",   "drives", "rims",  "ground",  "state",  "forces",
                             "m_inv",  "i_inv",  "dt",    "max2",    "extent", "run",
                             "radius", "sub",    "reach", "pairs_a", "pairs_b", "boxes",
                             "touched", "threads", NULL};
    PyObject *o[15];
    double dt, max2, extent, reach_m;
    int threads = 1;
    if (c->n_views) {
        PyErr_SetString(PyExc_RuntimeError, "Columns is initialised once");
        return -1;
    }
    if (!PyArg_ParseTupleAndKeywords(args, kwds, "OOOOOOOOdddOOOdOOOO|$i", kwlist, &o[0],
                                     &o[1], &o[2], &o[3], &o[4], &o[5], &o[6], &o[7], &dt,
                                     &max2, &extent, &o[8], &o[9], &o[10], &reach_m, &o[11],
                                     &o[12], &o[13], &o[14], &threads))
        return -1;
    if (threads < 1 || threads > POOL_MAX) {
        PyErr_Format(PyExc_ValueError, "threads: 1 to %d, got %d", POOL_MAX, threads);
        return -1;
    }
    c->threads = threads;
    Py_buffer probe;
    if (PyObject_GetBuffer(o[4], &probe, PyBUF_SIMPLE) < 0)
        return -1;
    const Py_ssize_t n = probe.len / (6 * 8);
    PyBuffer_Release(&probe);
    Py_ssize_t n_pairs = PyObject_Length(o[11]);
    Py_ssize_t n_runs = PyObject_Length(o[14]);
    Py_ssize_t n_boxes = PyObject_Length(o[13]);
    if (n_pairs < 0 || n_runs < 0 || n_boxes < 0)
        return -1;
    Stepper *st = &c->st;
    memset(st, 0, sizeof *st);
    st->n = n;
    if (!(st->plan = column_buffer(c, o[0], "plan", n * PLAN_WIDTH, 8, "d", 0)) ||
        !(st->drives = column_buffer(c, o[1], "drives", 2 * n, 8, "d", 0)) ||
        !(st->rims = column_buffer(c, o[2], "rims", 2 * n, 8, "d", 1)) ||
        !(st->ground = column_buffer(c, o[3], "ground", GROUND_TERMS * n, 8, "d", 0)) ||
        !(st->state = column_buffer(c, o[4], "state", 6 * n, 8, "d", 1)) ||
        !(c->forces = column_buffer(c, o[5], "forces", 3 * n, 8, "d", 1)) ||
        !(c->m_inv = column_buffer(c, o[6], "m_inv", n, 8, "d", 0)) ||
        !(c->i_inv = column_buffer(c, o[7], "i_inv", n, 8, "d", 0)) ||
        !(c->run = column_buffer(c, o[8], "run", n, 8, NULL, 0)) ||
        !(c->radius = column_buffer(c, o[9], "radius", n, 8, "d", 0)) ||
        !(c->sub = column_buffer(c, o[10], "sub", n, 8, "d", 0)) ||
        !(c->pa = column_buffer(c, o[11], "pairs_a", n_pairs, 8, NULL, 0)) ||
        !(c->pb = column_buffer(c, o[12], "pairs_b", n_pairs, 8, NULL, 0)) ||
        !(c->boxes = column_buffer(c, o[13], "boxes", 4 * n_boxes, 8, "d", 0)) ||
        !(c->touched = column_buffer(c, o[14], "touched", n_runs, 1, "B", 1)))
        return -1;
    for (Py_ssize_t k = 0; k < n; k++)
        if (c->run[k] < 0 || c->run[k] >= n_runs) {
            PyErr_SetString(PyExc_ValueError, "run: a rover's run beyond touched");
            return -1;
        }
    for (Py_ssize_t p = 0; p < n_pairs; p++)
        if (c->pa[p] < 0 || c->pa[p] >= n || c->pb[p] < 0 || c->pb[p] >= n) {
            PyErr_SetString(PyExc_ValueError, "pairs: a rover index out of range");
            return -1;
        }
    c->reach = PyMem_Malloc((n ? 2 * n : 1) * sizeof(double));
    c->miss = PyMem_Malloc((n ? n : 1) * sizeof(Py_ssize_t));
    st->rot = PyMem_Malloc((n ? 3 * n : 1) * sizeof(double));
    if (c->reach == NULL || c->miss == NULL || st->rot == NULL) {
        PyErr_NoMemory();
        return -1;
    }
    for (Py_ssize_t k = 0; k < n; k++) { /* the state given: computed as rover_forces does */
        const double a = st->state[6 * k + 2];
        st->rot[3 * k] = a;
        st->rot[3 * k + 1] = cos(a);
        st->rot[3 * k + 2] = sin(a);
    }
    st->rot_ahead = 1;
    st->rim_k = 1;
    st->rim_side = n;
    st->ground_k = 1;
    for (int t = 0; t < GROUND_TERMS; t++)
        st->ground_off[t] = ground_rows[t] * n;
    st->dt = dt;
    c->n_pairs = n_pairs;
    c->n_boxes = n_boxes;
    c->n_runs = n_runs;
    c->reach_m = reach_m;
    c->max2 = max2;
    c->extent = extent;
    return 0;
}

/* ---- Columns.advance_many: a run of steps in one call, touched runs frozen --------------
 * Why: the vector env (gym/vecepisode.py) steps 25 physics steps per agent step; one
 * Python call per step (the hook, the model, the screening's bookkeeping) cost ~60 us each
 * whatever the batch's size, more than the arithmetic of a small batch. The engine hands a
 * run of physics-only instants to one call (Simulation.batch_hook); this takes them here.
 * Each step is Columns_advance's two parts (called, not copied: whatever that step does,
 * these do), and with ``freeze`` the rows of every rover whose run is marked touched (this
 * step's screening included) are then put back where they were before the step (only
 * those rows are kept aside, and only once some run is marked), as
 * gym/veccolumns.py's EpisodeColumns puts them back in numpy (their forces and rims are
 * computed as there). Stops after the first step whose check fails (a frozen row may fail
 * it before it is put back: the caller looks for the violation in the rows as they are):
 * returns (steps taken, whether all passed). */
static PyObject *Columns_advance_many(Columns *c, PyObject *args)
{
    Py_ssize_t count;
    int freeze;
    if (!PyArg_ParseTuple(args, "np", &count, &freeze))
        return NULL;
    const Py_ssize_t n = c->st.n;
    double *s = c->st.state;
    double *before = NULL; /* the frozen rows before the step (allocated when first needed) */
    Py_ssize_t done = 0;
    int ok = 1, no_memory = 0;
    /* no Python API in the loop: other Python threads run meanwhile (and the pool's) */
    Py_BEGIN_ALLOW_THREADS
    while (done < count && ok) {
        Columns_screen(c);
        /* the rows to hold: those of runs marked, this step's screening included (the
         * screening reads the state, never writes it: these are the rows before the step) */
        int held = 0;
        if (freeze)
            for (Py_ssize_t r = 0; r < c->n_runs && !held; r++)
                held = c->touched[r] != 0;
        if (held) {
            if (before == NULL && (before = PyMem_RawMalloc(6 * n * sizeof(double))) == NULL) {
                no_memory = 1;
                break;
            }
            for (Py_ssize_t k = 0; k < n; k++)
                if (c->touched[c->run[k]])
                    memcpy(before + 6 * k, s + 6 * k, 6 * sizeof(double));
        }
        ok = Columns_move(c);
        if (held)
            for (Py_ssize_t k = 0; k < n; k++)
                if (c->touched[c->run[k]])
                    memcpy(s + 6 * k, before + 6 * k, 6 * sizeof(double));
        done++;
    }
    Py_END_ALLOW_THREADS
    PyMem_RawFree(before);
    if (no_memory)
        return PyErr_NoMemory();
    return Py_BuildValue("(nO)", done, ok ? Py_True : Py_False);
}

static PyMethodDef Columns_methods[] = {
    {"advance", (PyCFunction)Columns_advance, METH_NOARGS,
     "Screen for contacts, compute forces, integrate, check: whether every rover passed the "
     "safety check."},
    {"advance_many", (PyCFunction)Columns_advance_many, METH_VARARGS,
     "advance_many(count, freeze): up to count steps as advance() takes them (touched runs' "
     "rows held in place when freeze), stopping after a failed check: (steps, all passed)."},
    {NULL, NULL, 0, NULL},
};

static PyObject *Columns_workers(Columns *c, void *Py_UNUSED(closure))
{
    return PyLong_FromLong(c->pool == NULL ? 0 : c->pool->running);
}

static PyGetSetDef Columns_getset[] = {
    {"workers", (getter)Columns_workers, NULL,
     "Helper threads running beside the caller's (0 before the first threaded step).", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyTypeObject ColumnsType = {
    PyVarObject_HEAD_INIT(NULL, 0).tp_name = "amsa_phys.physics._step.Columns",
    .tp_basicsize = sizeof(Columns),
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "A batch's physics step over the arrays of physics/columns.py.",
    .tp_new = PyType_GenericNew,
    .tp_init = (initproc)Columns_init,
    .tp_dealloc = (destructor)Columns_dealloc,
    .tp_methods = Columns_methods,
    .tp_getset = Columns_getset,
};

/* ---- column_powers: the robots' power commands into a batch's drives ---------------------
 * Why: ColumnPhysics.set_powers did it in ~14 numpy calls (~14 us for 16 runs, three or four
 * times a vector env's step) for what is a handful of compares a rover. The same rule as
 * there and as PhysicsWorld.set_powers per rover: NaN is -100, then clipped to [-100, 100],
 * then 0.0 inside the driver's deadband (-band < v < band); rover index[j] gets left[j] in
 * drives row 0 and right[j] in row 1 of the (2, n) array. */
static inline double power_rule(double v, double band)
{
    if (v != v)
        v = -100.0;
    else if (v < -100.0)
        v = -100.0;
    else if (v > 100.0)
        v = 100.0;
    return (-band < v && v < band) ? 0.0 : v;
}

static PyObject *column_powers(PyObject *Py_UNUSED(module), PyObject *args)
{
    PyObject *objs[5];
    if (!PyArg_ParseTuple(args, "OOOOO", &objs[0], &objs[1], &objs[2], &objs[3], &objs[4]))
        return NULL;
    static const char *names[5] = {"left", "right", "index", "band", "drives"};
    Py_buffer views[5];
    PyObject *result = NULL;
    const int held = acquire_views(objs, views, names, "ddidw", 5);
    if (held < 5)
        goto done;
    Py_ssize_t m = views[2].len / 8, n = views[3].len / 8;
    if (views[0].len != m * 8 || views[1].len != m * 8 || views[4].len != 2 * n * 8) {
        PyErr_SetString(PyExc_ValueError, "column_powers: left, right and index of one length, "
                                          "drives (2, len(band))");
        goto done;
    }
    const double *left = views[0].buf, *right = views[1].buf, *band = views[3].buf;
    const int64_t *index = views[2].buf;
    double *drives = views[4].buf;
    for (Py_ssize_t j = 0; j < m; j++)
        if (index[j] < 0 || index[j] >= n) {
            PyErr_SetString(PyExc_IndexError, "column_powers: a rover index out of range");
            goto done;
        }
    for (Py_ssize_t j = 0; j < m; j++) {
        const Py_ssize_t k = (Py_ssize_t)index[j];
        drives[k] = power_rule(left[j], band[k]);
        drives[n + k] = power_rule(right[j], band[k]);
    }
    result = Py_None;
    Py_INCREF(result);
done:
    for (int i = 0; i < held; i++)
        PyBuffer_Release(&views[i]);
    return result;
}

/* ---- observe_rows: the vector env's relative observations, row by row in C --------------
 * Why: gym/observe.py's Observer.of_rows built them in ~25 numpy calls a vector step (~40 us
 * for 16 envs, more than the rovers' physics). The same arithmetic per element as there and
 * as the single env's of_values: the own heading's cos and sin (libm's, as math.cos and
 * math.sin), each other position as (c dx + s dy) / range and (-s dx + c dy) / range, each
 * remaining input divided by its scale (metres, speeds), then the scalar clip (above 1 is
 * 1, below -1 or NaN is -1). rows (n, m); own: (x, y, heading) columns or none; pairs:
 * (x, y) columns, flattened; rest: columns; scales: their divisors; out (n, 2 pairs + rest). */
static double observe_clip(double v)
{
    return v > 1.0 ? 1.0 : (v >= -1.0 ? v : -1.0);
}

static PyObject *observe_rows(PyObject *Py_UNUSED(module), PyObject *args)
{
    PyObject *objs[6];
    double range_m;
    if (!PyArg_ParseTuple(args, "OOOOOOd", &objs[0], &objs[1], &objs[2], &objs[3], &objs[4],
                          &objs[5], &range_m))
        return NULL;
    static const char *names[6] = {"rows", "own", "pairs", "rest", "scales", "out"};
    Py_buffer views[6];
    PyObject *result = NULL;
    const int held = acquire_views(objs, views, names, "diiidw", 6);
    if (held < 6)
        goto done;
    const Py_ssize_t n_own = views[1].len / 8, n_pairs = views[2].len / 16;
    const Py_ssize_t n_rest = views[3].len / 8;
    const Py_ssize_t width = 2 * n_pairs + n_rest;
    if ((n_own != 0 && n_own != 3) || (n_own == 0 && n_pairs != 0) ||
        views[2].len != n_pairs * 16 || views[4].len != n_rest * 8 || width == 0 ||
        views[5].len % (width * 8) != 0) {
        PyErr_SetString(PyExc_ValueError, "observe_rows: own (3 columns or none), pairs, rest "
                                          "and scales of matching lengths, out (n, width)");
        goto done;
    }
    const Py_ssize_t n = views[5].len / (width * 8);
    const Py_ssize_t m = n ? views[0].len / (n * 8) : 0;
    if (views[0].len != n * m * 8) {
        PyErr_SetString(PyExc_ValueError, "observe_rows: rows and out of different lengths");
        goto done;
    }
    const int64_t *own = views[1].buf, *pairs = views[2].buf, *rest = views[3].buf;
    for (Py_ssize_t j = 0; j < n_own; j++)
        if (own[j] < 0 || own[j] >= m) goto bad_index;
    for (Py_ssize_t j = 0; j < 2 * n_pairs; j++)
        if (pairs[j] < 0 || pairs[j] >= m) goto bad_index;
    for (Py_ssize_t j = 0; j < n_rest; j++)
        if (rest[j] < 0 || rest[j] >= m) goto bad_index;
    const double *rows = views[0].buf, *scales = views[4].buf;
    double *out = views[5].buf;
    for (Py_ssize_t r = 0; r < n; r++) {
        const double *row = rows + r * m;
        double *o = out + r * width;
        if (n_own) {
            const double h = row[own[2]], x0 = row[own[0]], y0 = row[own[1]];
            if (isinf(h)) { /* math.cos refuses it: so does the row-by-row path */
                PyErr_SetString(PyExc_ValueError, "math domain error");
                goto done;
            }
            const double c = cos(h), s = sin(h);
            for (Py_ssize_t p = 0; p < n_pairs; p++) {
                const double dx = row[pairs[2 * p]] - x0, dy = row[pairs[2 * p + 1]] - y0;
                o[2 * p] = observe_clip((c * dx + s * dy) / range_m);
                o[2 * p + 1] = observe_clip((-s * dx + c * dy) / range_m);
            }
        }
        for (Py_ssize_t j = 0; j < n_rest; j++)
            o[2 * n_pairs + j] = observe_clip(row[rest[j]] / scales[j]);
    }
    result = Py_None;
    Py_INCREF(result);
    goto done;
bad_index:
    PyErr_SetString(PyExc_IndexError, "observe_rows: a column beyond the rows' width");
done:
    for (int i = 0; i < held; i++)
        PyBuffer_Release(&views[i]);
    return result;
}

/* ---- steer_random: a random leader group's steering (physics/freerobot.py) ---------------
 * Why: FreeRobot._random_many did it in ~12 numpy calls and one Python math.cos call a copy
 * (its biggest part at 1,000 envs, most of the group's fixed cost at 16). The same operations
 * in the same order: power = cruise * factor; err = (heading - angle + pi) % (2 pi) - pi with
 * the floor-modulo of Python and numpy (fmod, then the divisor added when the signs differ,
 * +-0 given the divisor's sign); diff = gain * err; forward = power * (cos(err) if
 * cos(err) > 0 else 0, NaN giving 0); left = forward - diff, right = forward + diff. */

static inline void steer_one(double heading, double angle, double cruise, double factor,
                             double gain, double *left, double *right)
{
    const double pi = 3.141592653589793, two_pi = 2.0 * 3.141592653589793;
    const double power = cruise * factor;
    const double err = py_mod(heading - angle + pi, two_pi) - pi;
    const double diff = gain * err;
    const double c = cos(err);
    const double forward = power * (c > 0.0 ? c : 0.0);
    *left = forward - diff;
    *right = forward + diff;
}

static PyObject *steer_random(PyObject *Py_UNUSED(module), PyObject *args)
{
    PyObject *objs[7];
    if (!PyArg_ParseTuple(args, "OOOOOOO", &objs[0], &objs[1], &objs[2], &objs[3], &objs[4],
                          &objs[5], &objs[6]))
        return NULL;
    static const char *names[7] = {"heading", "angle", "cruise", "factor", "gain", "left",
                                   "right"};
    Py_buffer views[7];
    PyObject *result = NULL;
    const int held = acquire_views(objs, views, names, "dddddww", 7);
    if (held < 7)
        goto done;
    for (int i = 1; i < 7; i++)
        if (views[i].len != views[0].len) {
            PyErr_Format(PyExc_ValueError, "%s: as many float64 items as heading expected",
                         names[i]);
            goto done;
        }
    const Py_ssize_t n = views[0].len / 8;
    const double *heading = views[0].buf, *angle = views[1].buf, *cruise = views[2].buf;
    const double *factor = views[3].buf, *gain = views[4].buf;
    double *left = views[5].buf, *right = views[6].buf;
    for (Py_ssize_t k = 0; k < n; k++)
        steer_one(heading[k], angle[k], cruise[k], factor[k], gain[k], &left[k], &right[k]);
    result = Py_None;
    Py_INCREF(result);
done:
    for (int i = 0; i < held; i++)
        PyBuffer_Release(&views[i]);
    return result;
}

/* ---- robot_poses: a robot group's pose outputs (physics/robots.py) ----------------------
 * Why: ControlledRobot.step_many gathered them in ~12 numpy calls (two gathers, the heading's
 * wrap, the speed's cos and sin), three or four groups a vector env's step. Rover index[j]'s
 * row of the (N, 6) state and its two rims of the (2, N) rims go to column j of the (7, m)
 * out: x, y, (angle + pi) % (2 pi) - pi (the floor modulo, as Python's and numpy's), vx cos(a)
 * + vy sin(a) (libm's, what a run alone computes with math.cos and math.sin), w, left rim,
 * right rim. */
static inline void pose_one(const double *state, const double *rims, Py_ssize_t big_n,
                            Py_ssize_t k, double *out, Py_ssize_t m)
{
    const double pi = 3.141592653589793, two_pi = 2.0 * 3.141592653589793;
    const double *r = state + 6 * k;
    const double a = r[2];
    out[0] = r[0];
    out[m] = r[1];
    out[2 * m] = py_mod(a + pi, two_pi) - pi;
    out[3 * m] = r[3] * cos(a) + r[4] * sin(a);
    out[4 * m] = r[5];
    out[5 * m] = rims[k];
    out[6 * m] = rims[big_n + k];
}

static PyObject *robot_poses(PyObject *Py_UNUSED(module), PyObject *args)
{
    PyObject *objs[4];
    if (!PyArg_ParseTuple(args, "OOOO", &objs[0], &objs[1], &objs[2], &objs[3]))
        return NULL;
    static const char *names[4] = {"state", "rims", "index", "out"};
    Py_buffer views[4];
    PyObject *result = NULL;
    const int held = acquire_views(objs, views, names, "ddiw", 4);
    if (held < 4)
        goto done;
    const Py_ssize_t big_n = views[0].len / (6 * 8), m = views[2].len / 8;
    if (views[0].len != big_n * 6 * 8 || views[1].len != 2 * big_n * 8 ||
        views[3].len != 7 * m * 8) {
        PyErr_SetString(PyExc_ValueError, "robot_poses: state (N, 6), rims (2, N), out (7, "
                                          "len(index)) expected");
        goto done;
    }
    const double *state = views[0].buf, *rims = views[1].buf;
    const int64_t *index = views[2].buf;
    double *out = views[3].buf;
    for (Py_ssize_t j = 0; j < m; j++)
        if (index[j] < 0 || index[j] >= big_n) {
            PyErr_SetString(PyExc_IndexError, "robot_poses: a rover index out of range");
            goto done;
        }
    for (Py_ssize_t j = 0; j < m; j++)
        pose_one(state, rims, big_n, (Py_ssize_t)index[j], out + j, m);
    result = Py_None;
    Py_INCREF(result);
done:
    for (int i = 0; i < held; i++)
        PyBuffer_Release(&views[i]);
    return result;
}

/* ---- leader_step: a random leader group's whole step (physics/freerobot.py) -------------
 * Why: a random leader group (2.5 times a vector env's step) did steer_random, then
 * ControlledRobot.step_many's column_powers and robot_poses: three calls, the angles
 * gathered for the first, and ~8 us of Python around them whatever the batch's size. This
 * is the three, one rover at a time, with their helpers (so their floats): rover index[j]'s
 * steering from its angle (steer_one), its powers into the (2, n) drives (power_rule: the
 * drives are read by no pose), its pose outputs into column j of the (7, m) out
 * (pose_one). heading, cruise, factor, gain: (m,); band: (n,), as column_powers'. */
static PyObject *leader_step(PyObject *Py_UNUSED(module), PyObject *args)
{
    PyObject *objs[10];
    if (!PyArg_ParseTuple(args, "OOOOOOOOOO", &objs[0], &objs[1], &objs[2], &objs[3], &objs[4],
                          &objs[5], &objs[6], &objs[7], &objs[8], &objs[9]))
        return NULL;
    static const char *names[10] = {"heading", "state", "rims", "index", "cruise",
                                    "factor",  "gain",  "band", "drives", "out"};
    Py_buffer views[10];
    PyObject *result = NULL;
    const int held = acquire_views(objs, views, names, "dddiddddww", 10);
    if (held < 10)
        goto done;
    const Py_ssize_t m = views[3].len / 8, big_n = views[1].len / (6 * 8);
    if (views[0].len != m * 8 || views[4].len != m * 8 || views[5].len != m * 8 ||
        views[6].len != m * 8 || views[1].len != big_n * 6 * 8 || views[2].len != 2 * big_n * 8 ||
        views[7].len != big_n * 8 || views[8].len != 2 * big_n * 8 || views[9].len != 7 * m * 8) {
        PyErr_SetString(PyExc_ValueError, "leader_step: heading, index, cruise, factor, gain "
                                          "(m,), state (N, 6), rims (2, N), band (N,), drives "
                                          "(2, N), out (7, m) expected");
        goto done;
    }
    const double *heading = views[0].buf, *state = views[1].buf, *rims = views[2].buf;
    const int64_t *index = views[3].buf;
    const double *cruise = views[4].buf, *factor = views[5].buf, *gain = views[6].buf;
    const double *band = views[7].buf;
    double *drives = views[8].buf, *out = views[9].buf;
    for (Py_ssize_t j = 0; j < m; j++)
        if (index[j] < 0 || index[j] >= big_n) {
            PyErr_SetString(PyExc_IndexError, "leader_step: a rover index out of range");
            goto done;
        }
    for (Py_ssize_t j = 0; j < m; j++) {
        const Py_ssize_t k = (Py_ssize_t)index[j];
        double left, right;
        steer_one(heading[j], state[6 * k + 2], cruise[j], factor[j], gain[j], &left, &right);
        drives[k] = power_rule(left, band[k]);
        drives[big_n + k] = power_rule(right, band[k]);
        pose_one(state, rims, big_n, k, out + j, m);
    }
    result = Py_None;
    Py_INCREF(result);
done:
    for (int i = 0; i < held; i++)
        PyBuffer_Release(&views[i]);
    return result;
}

/* body_fields(address): the 14 doubles of a cpBody at the offsets the direct access reads
 * (cog, p, v, a, w, transform), for bodylayout.body_layout_ok to compare with what pymunk's
 * getters say of a body it set up; nothing else reads memory through it. */
static PyObject *body_fields(PyObject *Py_UNUSED(module), PyObject *arg)
{
    void *body = PyLong_AsVoidPtr(arg);
    if (body == NULL) {
        if (!PyErr_Occurred())
            PyErr_SetString(PyExc_ValueError, "a null body");
        return NULL;
    }
    const double *cog = body_at(body, BODY_COG), *p = body_at(body, BODY_P);
    const double *v = body_at(body, BODY_V), *t = body_at(body, BODY_T);
    return Py_BuildValue("(dddddddddddddd)", cog[0], cog[1], p[0], p[1], v[0], v[1],
                         *body_at(body, BODY_A), *body_at(body, BODY_W), t[0], t[1], t[2], t[3],
                         t[4], t[5]);
}

static PyMethodDef module_methods[] = {
    {"body_fields", body_fields, METH_O,
     "body_fields(address): a cpBody's cog, p, v, a, w and transform as the direct access reads them"},
    {"column_forces", column_forces, METH_VARARGS,
     "column_forces(plan, drives, rims, ground, state, forces, dt): every rover's force and "
     "torque into forces (n, 3), its rims advanced in place; no Space."},
    {"observe_rows", observe_rows, METH_VARARGS,
     "observe_rows(rows, own, pairs, rest, scales, out, range_m): the vector env's relative "
     "observations of every row (gym/observe.py), clipped to [-1, 1], into out."},
    {"column_powers", column_powers, METH_VARARGS,
     "column_powers(left, right, index, band, drives): power commands (NaN -100, clipped to "
     "+-100, 0 in the deadband) into the (2, n) drives of the rovers at index."},
    {"steer_random", steer_random, METH_VARARGS,
     "steer_random(heading, angle, cruise, factor, gain, left, right): a random leader "
     "group's wheel powers (physics/freerobot.py), into left and right."},
    {"robot_poses", robot_poses, METH_VARARGS,
     "robot_poses(state, rims, index, out): a robot group's pose outputs (x, y, heading, "
     "speed, yaw rate, rims) of the rovers at index into the (7, m) out."},
    {"leader_step", leader_step, METH_VARARGS,
     "leader_step(heading, state, rims, index, cruise, factor, gain, band, drives, out): a "
     "random leader group's step (physics/freerobot.py): steer_random, column_powers and "
     "robot_poses per rover."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef step_module = {
    PyModuleDef_HEAD_INIT, "_step",
    "The compiled physics step (see _step.c); imported by amsa_phys.physics.compiled.", -1,
    module_methods,
};

PyMODINIT_FUNC PyInit__step(void)
{
    if (PyType_Ready(&StepperType) < 0 || PyType_Ready(&ColumnsType) < 0)
        return NULL;
    PyObject *m = PyModule_Create(&step_module);
    if (m == NULL)
        return NULL;
    Py_INCREF(&StepperType);
    if (PyModule_AddObject(m, "Stepper", (PyObject *)&StepperType) < 0) {
        Py_DECREF(&StepperType);
        Py_DECREF(m);
        return NULL;
    }
    Py_INCREF(&ColumnsType);
    if (PyModule_AddObject(m, "Columns", (PyObject *)&ColumnsType) < 0) {
        Py_DECREF(&ColumnsType);
        Py_DECREF(m);
        return NULL;
    }
    PyObject *fields = PyTuple_New(PLAN_WIDTH);
    PyObject *rows = PyTuple_New(GROUND_TERMS);
    PyObject *slip = PyFloat_FromDouble(SLIP_SPEED_MIN);
    if (fields == NULL || rows == NULL || slip == NULL)
        goto fail;
    for (int i = 0; i < PLAN_WIDTH; i++) {
        PyObject *name = PyUnicode_FromString(plan_fields[i]);
        if (name == NULL)
            goto fail;
        PyTuple_SET_ITEM(fields, i, name);
    }
    for (int i = 0; i < GROUND_TERMS; i++) {
        PyObject *row = PyLong_FromLong(ground_rows[i]);
        if (row == NULL)
            goto fail;
        PyTuple_SET_ITEM(rows, i, row);
    }
    /* PyModule_AddObjectRef does not steal: the tuples are released below either way */
    if (PyModule_AddIntConstant(m, "PLAN_WIDTH", PLAN_WIDTH) < 0 ||
        PyModule_AddIntConstant(m, "SECOND_ORDER", 1) < 0 ||
        PyModule_AddIntConstant(m, "GROUND_TERMS", GROUND_TERMS) < 0 ||
        PyModule_AddObjectRef(m, "PLAN_FIELDS", fields) < 0 ||
        PyModule_AddObjectRef(m, "GROUND_ROWS", rows) < 0 ||
        PyModule_AddObjectRef(m, "SLIP_SPEED_MIN", slip) < 0)
        goto fail;
    Py_DECREF(fields);
    Py_DECREF(rows);
    Py_DECREF(slip);
    return m;
fail:
    Py_XDECREF(fields);
    Py_XDECREF(rows);
    Py_XDECREF(slip);
    Py_DECREF(m);
    return NULL;
}
