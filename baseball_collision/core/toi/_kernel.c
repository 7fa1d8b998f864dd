/*
 * The exact time-of-impact kernel of baseball_collision.core.toi, compiled (one implementation).
 *
 * Model (see ``toi/__init__.py``): over one interval the ball centre B, the bat tip (barrel end)
 * E and the knob S each move linearly. The bat is the segment S-E thickened by a radius (a
 * capsule); with R the sum of both radii, u = E - S and w = B - S (w = w0 + w1 tau,
 * u = u0 + u1 tau, tau in [0, 1]):
 *
 *   side (lambda = w.u / u.u in [0, 1]):  |w x u|^2 - R^2 |u|^2 = 0  (the seed's Eq. 15f)
 *   knob end (lambda < 0):                |w|^2 - R^2 = 0
 *   tip end (lambda > 1):                 |w - u|^2 - R^2 = 0
 *
 * A profile's piece is a round cone (the hull of the spheres at its two stations, radius R at
 * the knob end and R + d at the tip end): its side is the quartic
 * (|w|^2 - R^2)(|u|^2 - d^2) - (w.u + R d)^2 = 0 with lambda = (w.u + R d) / (|u|^2 - d^2), its
 * ends the spheres of their own radii (side_quartic, cone_closest; d = 0 is the capsule, to
 * the bit).
 *
 * Coordinates are shifted to the knob's start and scaled to the interval's extent before any
 * coefficient is formed. The end caps' quadratics are solved in closed form; the side's quartic
 * on its monotone pieces (the derivative chain: the roots of P'' split [0, 1] into pieces on
 * which P' is monotone, whose roots split it into pieces on which P is monotone), each crossing
 * refined by Newton steps safeguarded by bisection, then by up to four Newton steps on the gap
 * itself (a root in a cluster of the quartic's, where the bat shrinks to the point the ball
 * meets, is found to about eps^(1/4) and made exact there).
 * A tangential touch (a double root) is a local minimum within a slack of zero, never lost.
 *
 * Floating point: plain IEEE double arithmetic in the order the Python reference used, built
 * with -ffp-contract=off (no fused multiply-add, which gcc emits by default on arm64), so every
 * result is the same to the last bit on x86-64 and arm64.
 *
 * Python API (module ``_kernel``; the package wraps it in ``scalar`` and ``batch``):
 *   bind(ImpactResult, fields, features)  the result dataclass, its 7 field names (time, point,
 *                                     normal, bat_fraction, initially_overlapping, gap, feature)
 *                                     and the Feature members, once at import
 *   capsule(b0, b1, e0, e1, s0, s1, ball_radius, bat_radius, dt)
 *   profile(b0, b1, e0, e1, s0, s1, ball_radius, profile, dt)
 *        -> an ImpactResult, None (no contact) or NotImplemented (input that is not finite
 *           3-vectors, radii >= 0 and dt > 0: the caller checks it and raises)
 *   closest_offset(b0, b1, e0, e1, s0, s1) -> (x, y, z)
 *   capsule_rows(b0, b1, e0, e1, s0, s1, ball_radius, bat_radius, dt, out, start, stop)
 *        rows [start, stop) of contiguous float64 buffers (six (N, 3), three (N,), out (N,)),
 *        the GIL released: out = contact time in seconds or NaN
 *   first_contact(ball, bat, t_start, horizon, ball_radius, profile, tolerance, coarse_step)
 *        the prediction's search (core.prediction): the forecasts of ball (constant
 *        acceleration) and bat (a pivot turning about a fixed axis, or a commanded plan of
 *        poses) over the horizon, the coarse reach test and the chord sub-steps, each solved as
 *        profile() does -> (t, ImpactResult), None, or NotImplemented (forecasts not finite)
 *   forecast(ball, bat, t), bat_bounds(bat, ta, tb)  the same forecasts at one instant
 *   polyfit(times, rows, t, degree)  least squares by Householder QR (core.detector.kinematics)
 *   flight_fit(times, rows, degree)  a ball's flight fit by the same QR, flight_state(columns,
 *        centre, scale, t) its position and rate at t (core.motion.flight)
 *   ball_forecast(times, points, first, end, t0, degree, gravity, drag),
 *   bat_forecast(times, rows, first, end, degree)  the prediction's forecasts (core.prediction)
 *        fitted to a window of the detector's sample lists, read into contiguous arrays: the
 *        same QR and derivatives as polyfit + kinematics.derivatives, to the bit; ballistic()
 *        and bat_from_rates() the same forecasts from given rates (after a LAPACK fit), and
 *        least_accelerating(knob, tip) (kinematics)
 *   not_a_knot(times, rows, start), not_a_knot_quintic(times, rows, start), third_jumps(times),
 *   polynomial_basis(times, count), step_key(times), not_a_knot_penalty(times),
 *   beside_null(p, u, times, count, null_eigenvalue),
 *   likeliest(p, z, variances, bounds, grid, null_eigenvalue),
 *   smoothed(p, u, z, y, variances, bounds, weights, null_eigenvalue)  the smoothing weight and
 *        the smoothed values (core.motion.smoothing),
 *   c2_chart(samples, j, max_angle), bat_axis(sample),
 *   rotation_to(reference, direction), rotate(reference, rotation),
 *   turn_between(a, b)  how the bat turned between two samples (core.motion.base), and
 *        fill_turns(values, turns, first_kept, k) their sums (core.detector.streams),
 *   recharted(reference, origin, turn, rate, step),
 *   point_path_init(path, t0, t1, p0, p1, m0, m1)  a PointPath's slots (core.motion.points),
 *   c2_path_init(path, point_class, angle_class, t0, t1, sample0, sample1, knob_slopes,
 *        turn_slopes, length_slopes)  a C2BatPath's slots (core.motion.c2),
 *   window_bulge(times, rows, j, weights, offset, column, width)  the c2 far test's bulge
 *        bounds, c2_jump_bulge(times, values, breaks, steps, jumps, k, look_ahead, size,
 *        max_gap, bat, constants) its bound from kept per-sample chord-velocity jumps,
 *        bat_growth(times, rows, i, sample0, sample1, weights, far_offset, ratio) the bat's
 *        growth over a charted window (core.detector.broadphase.c2),
 *   c2_window(times, breaks, k, max_gap, look_ahead, size),
 *   reach_back(times, breaks, first, stop, max_gap, span, most),
 *   c2_inside(path, t)  a c2 bat path's knob and tip at t, zone_clear(ball_path, bat_path, ta,
 *        tb, n, ball_radius, profile, floor) whether a ball stays beyond floor from one
 *        (core.detector.sweep's near-miss zone),
 *   c2_deviation(knob, turn, length, ta, tb)  the c2 model's window fit (core.motion.splines,
 *        core.motion.c2, core.detector.fitting): the not-a-knot spline's slopes, the bat's
 *        chart, the window's samples and a c2 bat path's deviation bound
 *   bat_samples(cls, knob, tip, position, quaternion, first, last)  a chunk's bat samples as
 *        BatSample instances, and fast_forward_streams(plan, pos, end, ball, bat, walk, stop,
 *        noise, sample_class) a run of them taken into the streams (core.detector.chunks),
 *   point_residuals(times, points, start, count, scale, floor[, span])  tracker_noise auto's
 *        residuals, and NoiseMedian(capacity, scale, floor, min_count, rebuild[, span]) its
 *        running median estimate (core.detector.noise)
 *   trims(counts, cuts, trim_from, after, lengths)  a stream's trims over a chunk's plan,
 *   sorted_search(array, keys, right, out)  numpy.searchsorted walked for ascending keys,
 *   plan_rows(roles, stamps, values, origin, codes, offsets, limits, ...)  a chunk's rows as
 *        a plan's arrays and their value checks, order_checks(stamps, times, first, second,
 *        pre, limits, ok, gap)  a stream's order checks (core.detector.plans)
 *   hull_separation(b0, b1, k0, e0, k1, e1), far_spheres(b0, b1, k0, e0, k1, e1)  the scalar
 *        far test's hull bound and its spheres (core.detector.broadphase.scalar),
 *   c2_margins(ball, knob, tip, ball_k, bat_k, ball_times, bat_times, ball_closed, bat_closed,
 *        look_ahead, size, margin, constants, out, hull_reach)  the c2 far test over a chunk's
 *        union intervals (core.detector.broadphase.arrays), and departure_reaches(points, times, k,
 *        closed, out) the ball's departure reach over them, kept_parabola(times, values,
 *        breaks, aligned, k, max_gap) its free flight over one, kept per interval, and
 *        leaves_flight(times, values, breaks, aligned, k, noise, max_gap, rules) whether its
 *        closing sample left it (core.detector.departure)
 *   and the building blocks, for the tests: quadratic_roots, bracketed_root, critical_points,
 *   touch_candidates, quadratic_entry, cap_quadratics, side_quartic.
 *
 * Numpy float64 rows of shape (3,) are read from the array struct when built with numpy's
 * headers (KERNEL_NUMPY_ROWS, setup.py), else through the buffer protocol: the same numbers.
 * A plan's pivot travel sums sqrt(dx^2 + dy^2 + dz^2) where the Python it replaced used
 * math.dist: a bound for the reach test only, it never moved a prediction (9,908 compared).
 */

#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <structmember.h>
#ifdef KERNEL_NUMPY_ROWS
/* only the array struct's accessors (inline, no numpy C-API table: no import_array) */
#define NPY_NO_DEPRECATED_API NPY_1_7_API_VERSION
#include <numpy/ndarraytypes.h>
#endif

#include <math.h>
#include <stdbool.h>
#include <string.h>

#define TOUCH_TOLERANCE 1e-9 /* a gap (m) at or below which ball and bat count as touching */
#define DEGENERATE_AXIS 1e-24 /* |u|^2 in scaled units below which the bat has no axis */
#define ROOT_SLACK 1e-10 /* scaled gap allowed at a side root for rounding */
#define POLISH_STEPS 4 /* Newton steps on the gap at most, polishing a root */
#define POLISH_REACH 1e-3 /* the longest polishing step (of the interval): a quartic's root in a
                             cluster of four (a bat shrinking to a point where the ball meets
                             it) is off by about eps^(1/4), 1e-4; a graze's step is longer */
#define MAX_SEGMENTS 64 /* pieces (round cones) of one bat profile */

typedef struct {
  double x, y, z;
} Vec;

/* ------------------------------------------------------------------------------------------ */
/* vectors (the operations of core.geometry, in the same order) */

static inline Vec v_sub(Vec a, Vec b) { return (Vec){a.x - b.x, a.y - b.y, a.z - b.z}; }
static inline Vec v_scale(Vec a, double s) { return (Vec){a.x * s, a.y * s, a.z * s}; }
static inline Vec v_advance(Vec p0, Vec p1, double s)
{
  return (Vec){p0.x + p1.x * s, p0.y + p1.y * s, p0.z + p1.z * s};
}
static inline Vec v_lerp(Vec a, Vec b, double s)
{
  return (Vec){a.x + (b.x - a.x) * s, a.y + (b.y - a.y) * s, a.z + (b.z - a.z) * s};
}
static inline double v_dot(Vec a, Vec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline Vec v_cross(Vec a, Vec b)
{
  return (Vec){a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
static inline double min_of(double a, double b) { return b < a ? b : a; } /* Python's min */
static inline double max_of(double a, double b) { return b > a ? b : a; } /* Python's max */
static inline bool finite3(Vec a) { return isfinite(a.x) && isfinite(a.y) && isfinite(a.z); }
/* every coordinate of n points finite: x - x is 0 for a finite x and NaN for an infinity or a
   NaN, and a NaN stays NaN in a sum (one branch for all of them) */
static inline bool finite_points(const Vec *p, int n)
{
  double probe = 0.0;
  for (int i = 0; i < n; i++) {
    probe += (p[i].x - p[i].x) + (p[i].y - p[i].y) + (p[i].z - p[i].z);
  }
  return probe == 0.0;
}

/* Fraction along start-end (clipped to [0, 1]) of the closest point to p; the point in *closest */
static double closest_on_segment(Vec p, Vec start, Vec end, Vec *closest)
{
  Vec axis = v_sub(end, start);
  double axis2 = v_dot(axis, axis);
  double fraction = 0.0;
  if (axis2 != 0.0) {
    fraction = min_of(1.0, max_of(0.0, v_dot(v_sub(p, start), axis) / axis2));
  }
  *closest = v_lerp(start, end, fraction);
  return fraction;
}

/*
 * Fraction along start-end (clipped to [0, 1]) of the axis point whose sphere is nearest p, on a
 * round cone whose radius grows by dr from start to end (the hull of the spheres at its ends:
 * the distance from p to the sphere at fraction f, |p - a(f)| - r0 - f dr, is convex in f; its
 * minimum lies dr d / (L sqrt(L^2 - dr^2)) past the foot of p's perpendicular, d the distance
 * from the axis and L the length). The point in *closest. dr 0: closest_on_segment, the same
 * bits; an axis no longer than |dr| (one end's sphere holds the other's): the larger end.
 */
static double cone_closest(Vec p, Vec start, Vec end, double dr, Vec *closest)
{
  if (dr == 0.0) {
    return closest_on_segment(p, start, end, closest);
  }
  Vec axis = v_sub(end, start);
  double axis2 = v_dot(axis, axis), fraction = dr > 0.0 ? 1.0 : 0.0;
  if (axis2 > dr * dr) {
    Vec offset = v_sub(p, start);
    double along = v_dot(offset, axis) / axis2;
    Vec across = v_sub(offset, v_scale(axis, along));
    double slide = dr * sqrt(v_dot(across, across)) / sqrt(axis2 * (axis2 - dr * dr));
    fraction = min_of(1.0, max_of(0.0, along + slide));
  }
  *closest = v_lerp(start, end, fraction);
  return fraction;
}

/* offset as a unit vector; for a ball centre on the axis, a unit vector across the axis */
static Vec unit_normal(Vec offset, Vec axis, Vec relative_velocity)
{
  double length = sqrt(v_dot(offset, offset));
  if (1e-12 < length && length < INFINITY) {
    return v_scale(offset, 1.0 / length);
  }
  double axis2 = v_dot(axis, axis);
  Vec candidates[3] = {v_scale(relative_velocity, -1.0), {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}};
  for (int i = 0; i < 3; i++) {
    Vec candidate = candidates[i];
    if (axis2 > 0.0) {
      double along = v_dot(candidate, axis) / axis2;
      candidate = v_sub(candidate, v_scale(axis, along));
    }
    length = sqrt(v_dot(candidate, candidate));
    if (1e-12 < length && length < INFINITY) {
      return v_scale(candidate, 1.0 / length);
    }
  }
  return (Vec){0.0, 0.0, 1.0};
}

/* ------------------------------------------------------------------------------------------ */
/* polynomials on [0, 1], lowest power first (a quartic; lower degrees have zero tops) */

static inline double poly(const double *c, double x)
{
  return c[0] + x * (c[1] + x * (c[2] + x * (c[3] + x * c[4])));
}
static inline double poly_d1(const double *c, double x)
{
  return c[1] + x * (2.0 * c[2] + x * (3.0 * c[3] + x * 4.0 * c[4]));
}
static inline double poly_d2(const double *c, double x)
{
  return 2.0 * c[2] + x * (6.0 * c[3] + x * 12.0 * c[4]);
}
/* the order-th derivative (0 or 1) and the next one */
static inline double poly_order(const double *c, int order, double x)
{
  return order == 0 ? poly(c, x) : poly_d1(c, x);
}
static inline double poly_slope(const double *c, int order, double x)
{
  return order == 0 ? poly_d1(c, x) : poly_d2(c, x);
}

/* real roots of a x^2 + b x + c, ascending (numerically stable form); returns how many */
static int quadratic_roots(double a, double b, double c, double *roots)
{
  if (a == 0.0) {
    if (b == 0.0) {
      return 0;
    }
    roots[0] = -c / b;
    return 1;
  }
  double disc = b * b - 4.0 * a * c;
  if (disc < 0.0) {
    return 0;
  }
  double q = -0.5 * (b + copysign(sqrt(disc), b));
  if (q == 0.0) {
    roots[0] = roots[1] = 0.0;
    return 2;
  }
  double r1 = q / a, r2 = c / q;
  roots[0] = r1 <= r2 ? r1 : r2;
  roots[1] = r1 <= r2 ? r2 : r1;
  return 2;
}

/*
 * Root of the order-th derivative of c, monotone on [lo, hi] and changing sign there, to double
 * precision: Newton steps safeguarded by bisection. f_lo is its value at lo (not zero).
 */
static double bracketed_root(const double *c, int order, double lo, double hi, double f_lo)
{
  bool positive = f_lo > 0.0;
  double x = 0.5 * (lo + hi);
  for (int i = 0; i < 200; i++) {
    double fx = poly_order(c, order, x);
    if (fx == 0.0) {
      return x;
    }
    if ((fx > 0.0) == positive) {
      lo = x;
    } else {
      hi = x;
    }
    double slope = poly_slope(c, order, x);
    double step = slope != 0.0 ? fx / slope : INFINITY;
    double candidate = x - step;
    if (!(lo < candidate && candidate < hi)) {
      candidate = 0.5 * (lo + hi);
    }
    if (fabs(candidate - x) <= 1e-16 || hi - lo <= 2e-16) {
      return candidate;
    }
    x = candidate;
  }
  return x;
}

/*
 * The points in (0, 1) where the quartic changes direction, found one at a time in ascending
 * order (a walk stops at the first contact, so the later ones are mostly never needed): the
 * roots of c'' split [0, 1] into pieces on which c' is monotone; a piece where c' changes sign
 * holds one. A zero of c' exactly at an inflection (a stationary inflection) is skipped.
 */
typedef struct {
  int piece, n_bounds;
  double bounds[4];
} Turns;

static void turns_start(const double *c, Turns *turns)
{
  double roots[2];
  int found = quadratic_roots(12.0 * c[4], 6.0 * c[3], 2.0 * c[2], roots);
  turns->n_bounds = 0;
  turns->piece = 0;
  turns->bounds[turns->n_bounds++] = 0.0;
  for (int i = 0; i < found; i++) {
    if (0.0 < roots[i] && roots[i] < 1.0) {
      turns->bounds[turns->n_bounds++] = roots[i];
    }
  }
  turns->bounds[turns->n_bounds++] = 1.0;
}

/* the next point where the quartic changes direction into *out; false when there are no more */
static bool next_turn(const double *c, Turns *turns, double *out)
{
  while (turns->piece + 1 < turns->n_bounds) {
    double lo = turns->bounds[turns->piece], hi = turns->bounds[turns->piece + 1];
    turns->piece++;
    double d_lo = poly_d1(c, lo), d_hi = poly_d1(c, hi);
    if ((d_lo < 0.0 && d_hi > 0.0) || (d_lo > 0.0 && d_hi < 0.0)) {
      *out = bracketed_root(c, 1, lo, hi, d_lo);
      return true;
    }
  }
  return false;
}

/* all of them, ascending; returns how many (<= 3) */
static int critical_points(const double *c, double *out)
{
  Turns turns;
  int count = 0;
  turns_start(c, &turns);
  while (next_turn(c, &turns, &out[count])) {
    count++;
  }
  return count;
}

/* The slack of a gap polynomial at x: slack_scale * poly(slack_poly, x) */
typedef struct {
  double scale;
  const double *poly;
} Slack;

static inline double slack_at(Slack slack, double x) { return slack.scale * poly(slack.poly, x); }

/*
 * The times in [0, 1] at which a gap polynomial c starts to count as contact, in order, one per
 * call: *state starts at 0 and is advanced; returns false when there are no more. Gives 0 when
 * touching at the start, each root where c enters <= 0, and each local minimum within the slack
 * without crossing (a graze).
 */
typedef struct {
  int stage; /* 0: the start; 1: the pieces found so far; 2: the last piece, up to 1, walked */
  Turns turns;
  double a, f_a;
} Candidates;

static bool next_candidate(const double *c, Slack slack, Candidates *it, double *tau)
{
  if (it->stage == 0) {
    it->stage = 1;
    it->a = 0.0;
    it->f_a = poly(c, 0.0);
    turns_start(c, &it->turns); /* closed form; each turn is found only when the walk needs it */
    if (it->f_a <= slack_at(slack, 0.0)) {
      *tau = 0.0;
      return true;
    }
  }
  while (it->stage == 1) {
    double b;
    if (!next_turn(c, &it->turns, &b)) {
      b = 1.0;
      it->stage = 2;
    }
    double f_b = poly(c, b);
    double a = it->a, f_a = it->f_a;
    it->a = b;
    it->f_a = f_b;
    if (f_a > 0.0 && f_b <= 0.0) {
      *tau = bracketed_root(c, 0, a, b, f_a);
      return true;
    }
    if (0.0 < f_b && f_b < f_a && f_b <= slack_at(slack, b)) {
      *tau = b;
      return true;
    }
  }
  return false;
}

/*
 * First tau in [0, 1] at which a tau^2 + b tau + c (a >= 0) counts as contact: <= 0, or a local
 * minimum within slack (a graze). The candidates in closed form, for the end caps' quadratics.
 */
static bool quadratic_entry(double a, double b, double c, double slack, double *tau)
{
  if (c <= slack) {
    *tau = 0.0;
    return true;
  }
  double vertex;
  if (a > 0.0) {
    double disc = b * b - 4.0 * a * c;
    if (disc >= 0.0 && b < 0.0) {
      double q = -0.5 * (b - sqrt(disc));
      double root = min_of(q / a, c / q);
      if (root <= 1.0) {
        *tau = root;
        return true;
      }
    }
    vertex = min_of(1.0, -0.5 * b / a);
  } else {
    vertex = b < 0.0 ? 1.0 : 0.0;
  }
  if (vertex > 0.0 && a * vertex * vertex + b * vertex + c <= slack) {
    *tau = vertex;
    return true;
  }
  return false;
}

/* ------------------------------------------------------------------------------------------ */
/* the contact polynomials of one capsule */

typedef struct {
  Vec w0, w1, u0, u1; /* w = B - S and u = E - S in scaled units: w0 + w1 tau, u0 + u1 tau */
  double scale;
} Scaled;

/* the end caps' quadratics (a, b, c): a tau^2 + b tau + c = |p|^2 - R^2, p = w (knob, R^2 rr),
 * w - u (tip, R^2 rr_tip) */
static void cap_quadratics(const Scaled *s, double rr, double rr_tip, double caps[2][3])
{
  Vec v0 = v_sub(s->w0, s->u0), v1 = v_sub(s->w1, s->u1);
  caps[0][0] = v_dot(s->w1, s->w1);
  caps[0][1] = 2.0 * v_dot(s->w0, s->w1);
  caps[0][2] = v_dot(s->w0, s->w0) - rr;
  caps[1][0] = v_dot(v1, v1);
  caps[1][1] = 2.0 * v_dot(v0, v1);
  caps[1][2] = v_dot(v0, v0) - rr_tip;
}

/*
 * the side's quartic |w x u|^2 - rr |u|^2 and the quadratics |u|^2 and w.u (5 coefficients); on
 * a round cone (radius r at the knob end, r + d at the tip end, rr = r^2; d 0 for a capsule)
 * less d^2 |w|^2 + 2 r d w.u: (|w|^2 - r^2)(|u|^2 - d^2) - (w.u + r d)^2, zero where the ball
 * touches the sphere at fraction (w.u + r d) / (|u|^2 - d^2) (minimising |w - f u|^2 - (r + f d)^2)
 */
static void side_quartic(const Scaled *s, double rr, double r, double d, double *quartic,
                         double *uu, double *wu)
{
  Vec c0 = v_cross(s->w0, s->u0);
  Vec c1 = v_sub(v_cross(s->w0, s->u1), v_cross(s->u0, s->w1));
  Vec c2 = v_cross(s->w1, s->u1);
  uu[0] = v_dot(s->u0, s->u0);
  uu[1] = 2.0 * v_dot(s->u0, s->u1);
  uu[2] = v_dot(s->u1, s->u1);
  uu[3] = uu[4] = 0.0;
  quartic[0] = v_dot(c0, c0) - rr * uu[0];
  quartic[1] = 2.0 * v_dot(c0, c1) - rr * uu[1];
  quartic[2] = v_dot(c1, c1) + 2.0 * v_dot(c0, c2) - rr * uu[2];
  quartic[3] = 2.0 * v_dot(c1, c2);
  quartic[4] = v_dot(c2, c2);
  wu[0] = v_dot(s->w0, s->u0);
  wu[1] = v_dot(s->w0, s->u1) + v_dot(s->w1, s->u0);
  wu[2] = v_dot(s->w1, s->u1);
  wu[3] = wu[4] = 0.0;
  if (d != 0.0) {
    double ww[3] = {v_dot(s->w0, s->w0), 2.0 * v_dot(s->w0, s->w1), v_dot(s->w1, s->w1)};
    for (int i = 0; i < 3; i++) {
      quartic[i] -= d * d * ww[i] + 2.0 * r * d * wu[i];
    }
  }
}

/* the interval's points p (b0, b1, e0, e1, s0, s1) shifted to the knob and scaled */
static Scaled scaled(const Vec *p, double radius)
{
  Vec w0 = v_sub(p[0], p[4]), w_end = v_sub(p[1], p[5]);
  Vec u0 = v_sub(p[2], p[4]), u_end = v_sub(p[3], p[5]);
  double values[13] = {w0.x, w0.y, w0.z, w_end.x, w_end.y, w_end.z, u0.x, u0.y, u0.z,
                       u_end.x, u_end.y, u_end.z, radius};
  double extent = fabs(values[0]);
  for (int i = 1; i < 13; i++) {
    extent = max_of(extent, fabs(values[i]));
  }
  if (extent == 0.0) {
    extent = 1.0;
  }
  double inv = 1.0 / extent;
  Vec w0s = v_scale(w0, inv), wes = v_scale(w_end, inv);
  Vec u0s = v_scale(u0, inv), ues = v_scale(u_end, inv);
  return (Scaled){w0s, v_sub(wes, w0s), u0s, v_sub(ues, u0s), extent};
}

/* the gap between ball and capsule (round cone: radius r at the knob end, r + d at the tip)
 * at tau in scaled units, and d(gap)/d(tau) in *rate */
static double scaled_gap(const Scaled *s, double tau, double r, double d, double *rate)
{
  static const Vec origin = {0.0, 0.0, 0.0};
  Vec w = v_advance(s->w0, s->w1, tau), u = v_advance(s->u0, s->u1, tau), closest;
  double fraction = cone_closest(w, origin, u, d, &closest);
  Vec offset = v_sub(w, closest);
  double length = sqrt(v_dot(offset, offset));
  if (d != 0.0) {
    r += fraction * d;
  }
  if (length == 0.0) {
    *rate = 0.0;
    return -r;
  }
  /* the closest point slides along the axis, but the gap is least there: only the motion of
     the ball relative to the bat point at that fraction changes it to first order */
  *rate = v_dot(offset, v_sub(s->w1, v_scale(s->u1, fraction))) / length;
  return length - r;
}

/*
 * Refine a crossing root with Newton steps on the gap itself (well conditioned): POLISH_STEPS at
 * most; a step longer than POLISH_REACH (a graze, where the rate vanishes) or one that does not
 * reduce the gap is not taken. The scaled gap at the tau returned goes to *gap_out.
 */
static double polish(const Scaled *s, double tau, double r, double d, double *gap_out)
{
  double rate, gap = scaled_gap(s, tau, r, d, &rate);
  for (int i = 0; i < POLISH_STEPS; i++) {
    if (rate == 0.0 || gap == 0.0) {
      break;
    }
    double step = gap / rate;
    if (fabs(step) > POLISH_REACH || !(0.0 <= tau - step && tau - step <= 1.0) || tau - step == tau) {
      break; /* (a step within half a unit of tau's last place: the gap there is this one) */
    }
    double new_rate, new_gap = scaled_gap(s, tau - step, r, d, &new_rate);
    if (fabs(new_gap) >= fabs(gap)) {
      break;
    }
    tau = tau - step;
    gap = new_gap;
    rate = new_rate;
  }
  *gap_out = gap; /* the gap at the tau returned */
  return tau;
}

/* earliest tau in [0, 1] of contact (gap <= TOUCH_TOLERANCE) with a capsule of radius, or a
 * round cone of radius at the knob end and radius + growth at the tip end */
static bool first_contact_tau(const Scaled *s, double radius, double growth, double *out)
{
  double r = radius / s->scale, d = growth / s->scale;
  double rr = r * r, r_tip = r + d, rr_tip = d != 0.0 ? r_tip * r_tip : rr;
  double tol = TOUCH_TOLERANCE / s->scale;
  double cap_slack = (r + tol) * (r + tol) - rr;
  double slacks[2] = {cap_slack, d != 0.0 ? (r_tip + tol) * (r_tip + tol) - rr_tip : cap_slack};
  double caps[2][3], tau, best = 0.0;
  bool have = false;
  cap_quadratics(s, rr, rr_tip, caps);
  for (int i = 0; i < 2; i++) {
    if (quadratic_entry(caps[i][0], caps[i][1], caps[i][2], slacks[i], &tau) &&
        (!have || tau < best)) {
      best = tau;
      have = true;
    }
  }
  if (have && best == 0.0) {
    *out = 0.0; /* touching at the start: no side candidate can come earlier */
    return true;
  }
  if (have) {
    double gap;
    best = polish(s, best, r, d, &gap);
  }
  double quartic[5], uu[5], wu[5];
  side_quartic(s, rr, r, d, quartic, uu, wu);
  if (max_of(max_of(uu[0], fabs(uu[1])), uu[2]) <= DEGENERATE_AXIS) {
    *out = best; /* zero-length bat: a sphere, the end caps say it all */
    return have;
  }
  Candidates it = {0};
  Slack slack = {max_of(slacks[0], slacks[1]), uu};
  while (next_candidate(quartic, slack, &it, &tau)) {
    if (have && tau >= best) {
      break;
    }
    double axis2 = poly(uu, tau), along = poly(wu, tau);
    if (d != 0.0) { /* (the sphere the side's quartic touches, on a round cone) */
      axis2 -= d * d;
      along += r * d;
    }
    if (axis2 <= DEGENERATE_AXIS || !(0.0 <= along && along <= axis2)) {
      continue;
    }
    /* the quartic also vanishes where the bat's length passes through zero; the gap itself,
       at the polished root, confirms a root is a touch of the side */
    double polished = tau, gap, rate;
    if (tau > 0.0) {
      polished = polish(s, tau, r, d, &gap);
    } else {
      gap = scaled_gap(s, tau, r, d, &rate);
    }
    if (gap <= tol + ROOT_SLACK) {
      *out = have ? min_of(best, polished) : polished;
      return true;
    }
  }
  *out = best;
  return have;
}

/* ------------------------------------------------------------------------------------------ */
/* broad phase and one capsule */

/*
 * The points of an interval, p: b0, b1 (ball centre), e0, e1 (tip), s0, s1 (knob), passed by
 * pointer: six 3-vectors by value are copied onto the stack at every call that is not inlined.
 */

/* the ball's offset from the bat's midpoint at their closest, all moving on chords */
static Vec closest_offset(const Vec *p)
{
  Vec m0 = v_sub(p[0], v_lerp(p[4], p[2], 0.5));
  Vec m1 = v_sub(v_sub(p[1], v_lerp(p[5], p[3], 0.5)), m0);
  double m11 = v_dot(m1, m1);
  double s = m11 == 0.0 ? 0.0 : min_of(1.0, max_of(0.0, -v_dot(m0, m1) / m11));
  return v_advance(m0, m1, s);
}

/* conservative: false only when the ball certainly stays clear of the bat */
static bool may_touch(const Vec *p, double radius)
{
  Vec closest = closest_offset(p);
  Vec a0 = v_sub(p[2], p[4]), a1 = v_sub(p[3], p[5]);
  double half = 0.5 * sqrt(max_of(v_dot(a0, a0), v_dot(a1, a1))); /* = the larger root */
  double reach = half + radius + TOUCH_TOLERANCE;
  double margin = 1e-9 * (1.0 + reach);
  return v_dot(closest, closest) <= (reach + margin) * (reach + margin);
}

/* the first contact's tau with a round cone: both radii (ball and bat) radius at the knob end,
 * radius + growth at the tip end (growth 0: a capsule) */
static bool cone_tau(const Vec *p, double radius, double growth, double *tau)
{
  double largest = radius + max_of(0.0, growth);
  if (!may_touch(p, largest)) {
    return false;
  }
  Scaled s = scaled(p, largest);
  return first_contact_tau(&s, radius, growth, tau);
}

static bool capsule_tau(const Vec *p, double radius, double *tau)
{
  return cone_tau(p, radius, 0.0, tau);
}

/* ------------------------------------------------------------------------------------------ */
/* the result */

static PyObject *result_type = NULL; /* ImpactResult */
static PyObject *result_fields = NULL; /* its field names: time, point, normal, ..., feature */
static PyObject *features = NULL;      /* (SIDE, KNOB_END, TIP_END) */
static PyObject *no_arguments = NULL;  /* () */

/* where each field lives in an ImpactResult with __slots__ (bind finds them), or -1 */
static Py_ssize_t slot_offsets[7] = {-1, -1, -1, -1, -1, -1, -1};

/*
 * A new ImpactResult from its 7 field values (references stolen), filled in as the frozen
 * dataclass's own __init__ does, without the cost of calling it: straight into its slots (the
 * member descriptors' offsets), or, for a class without slots, into its instance dictionary.
 */
static PyObject *new_result(PyObject **values)
{
  bool ok = true;
  for (int i = 0; i < 7; i++) {
    ok = ok && values[i] != NULL;
  }
  if (ok && slot_offsets[0] >= 0) {
    PyTypeObject *type = (PyTypeObject *)result_type;
    PyObject *result = type->tp_alloc(type, 0);
    for (int i = 0; i < 7; i++) {
      if (result != NULL) {
        *(PyObject **)((char *)result + slot_offsets[i]) = values[i]; /* stolen */
      } else {
        Py_XDECREF(values[i]);
      }
    }
    return result;
  }
  PyObject *result = ok ? PyBaseObject_Type.tp_new((PyTypeObject *)result_type, no_arguments,
                                                   NULL)
                        : NULL;
  PyObject *dict = result ? PyObject_GenericGetDict(result, NULL) : NULL;
  for (int i = 0; dict != NULL && i < 7; i++) {
    if (PyDict_SetItem(dict, PyTuple_GET_ITEM(result_fields, i), values[i]) < 0) {
      Py_CLEAR(result);
      break;
    }
  }
  Py_XDECREF(dict);
  if (dict == NULL) {
    Py_CLEAR(result);
  }
  for (int i = 0; i < 7; i++) {
    Py_XDECREF(values[i]);
  }
  return result;
}

static PyObject *vec_tuple(Vec v)
{
  PyObject *x = PyFloat_FromDouble(v.x), *y = PyFloat_FromDouble(v.y);
  PyObject *z = PyFloat_FromDouble(v.z);
  PyObject *tuple = x && y && z ? PyTuple_New(3) : NULL;
  if (tuple == NULL) {
    Py_XDECREF(x);
    Py_XDECREF(y);
    Py_XDECREF(z);
    return NULL;
  }
  PyTuple_SET_ITEM(tuple, 0, x);
  PyTuple_SET_ITEM(tuple, 1, y);
  PyTuple_SET_ITEM(tuple, 2, z);
  return tuple;
}

/* the ImpactResult for contact at tau on a capsule piece spanning fractions f0-f1 of the bat
 * (a round cone: radius bat_radius at f0, tip_radius at f1), its spot within the bat's first
 * and last station (fractions lowest, highest) */
static PyObject *contact_at(double tau, double dt, const Vec *p, double ball_radius,
                            double bat_radius, double tip_radius, double f0, double f1,
                            bool knob_end, bool tip_end, double lowest, double highest)
{
  /* p: b0, b1, e0 (tip), e1, s0 (knob), s1 */
  Vec ball = v_lerp(p[0], p[1], tau), tip = v_lerp(p[2], p[3], tau);
  Vec knob = v_lerp(p[4], p[5], tau), centre;
  double local = cone_closest(ball, knob, tip, tip_radius - bat_radius, &centre);
  bool cone = tip_radius != bat_radius;
  if (cone) {
    bat_radius += (tip_radius - bat_radius) * local;
  }
  Vec bat_motion = v_lerp(v_sub(p[5], p[4]), v_sub(p[3], p[2]), local);
  Vec rel_velocity = v_scale(v_sub(v_sub(p[1], p[0]), bat_motion), 1.0 / dt);
  Vec normal = unit_normal(v_sub(ball, centre), v_sub(tip, knob), rel_velocity);
  Vec offset = v_sub(ball, centre);
  double gap = sqrt(v_dot(offset, offset)) - ball_radius - bat_radius;
  double fraction = f0 + (f1 - f0) * local;
  int feature = 0;
  if (local <= 0.0 && knob_end) {
    feature = 1;
  } else if (local >= 1.0 && tip_end) {
    feature = 2;
  }
  Vec point = {centre.x + normal.x * bat_radius, centre.y + normal.y * bat_radius,
               centre.z + normal.z * bat_radius};
  Vec axis = v_sub(tip, knob);
  double axis2 = v_dot(axis, axis);
  if ((cone || local <= 0.0 || local >= 1.0) && feature == 0 && axis2 > 0.0) {
    /* on a taper, or a piece's end sphere where it meets the next, the normal leans along the
       axis: the spot is the contact point's own place along it (a capsule side's is its
       sphere's centre, the same place) */
    fraction = f0 + (f1 - f0) * (local + bat_radius * v_dot(normal, axis) / axis2);
    fraction = min_of(highest, max_of(lowest, fraction));
  }
  if (result_type == NULL) {
    PyErr_SetString(PyExc_RuntimeError, "_kernel.bind() was not called");
    return NULL;
  }
  PyObject *feature_member = PyTuple_GET_ITEM(features, feature);
  Py_INCREF(feature_member);
  PyObject *values[7] = {PyFloat_FromDouble(tau * dt), vec_tuple(point), vec_tuple(normal),
                         PyFloat_FromDouble(fraction), PyBool_FromLong(tau == 0.0),
                         PyFloat_FromDouble(gap), feature_member};
  return new_result(values);
}

/* ------------------------------------------------------------------------------------------ */
/* argument conversion */

/* 3 numbers from a buffer of 3 contiguous float64 (a numpy row); -1: not such a buffer */
static int read_buffer_vec(PyObject *o, Vec *v)
{
  Py_buffer view;
  if (PyObject_GetBuffer(o, &view, PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) < 0) {
    PyErr_Clear();
    return -1;
  }
  int ok = view.len == 3 * (Py_ssize_t)sizeof(double) && view.itemsize == sizeof(double) &&
           view.format != NULL && (strcmp(view.format, "d") == 0 || strcmp(view.format, "<d") == 0 ||
                                   strcmp(view.format, "=d") == 0);
  if (ok) {
    const double *x = view.buf;
    *v = (Vec){x[0], x[1], x[2]};
  }
  PyBuffer_Release(&view);
  return ok ? 1 : -1;
}

#ifdef KERNEL_NUMPY_ROWS
static PyObject *ndarray_type = NULL; /* numpy.ndarray, found at import */

/*
 * 3 numbers from a numpy float64 array of shape (3,) (native byte order, aligned, any stride),
 * read from the array struct itself: a tenth of the buffer protocol's cost. -1: not such an
 * array.
 */
static int read_ndarray_vec(PyObject *o, Vec *v)
{
  PyArrayObject *array = (PyArrayObject *)o;
  if (PyArray_NDIM(array) != 1 || PyArray_DIM(array, 0) != 3 ||
      PyArray_DESCR(array)->type_num != NPY_DOUBLE || !PyArray_ISNOTSWAPPED(array) ||
      !PyArray_ISALIGNED(array)) {
    return -1;
  }
  const char *data = PyArray_DATA(array);
  npy_intp stride = PyArray_STRIDE(array, 0);
  *v = (Vec){*(const double *)data, *(const double *)(data + stride),
             *(const double *)(data + 2 * stride)};
  return 1;
}
#endif

/* 3 numbers from a sequence; false (no exception set) when it is not one */
static bool read_vec(PyObject *o, Vec *v)
{
#ifdef KERNEL_NUMPY_ROWS
  if ((PyObject *)Py_TYPE(o) == ndarray_type && read_ndarray_vec(o, v) == 1) {
    return true;
  }
#endif
  if (PyTuple_CheckExact(o) && PyTuple_GET_SIZE(o) == 3 && PyFloat_CheckExact(PyTuple_GET_ITEM(o, 0)) &&
      PyFloat_CheckExact(PyTuple_GET_ITEM(o, 1)) && PyFloat_CheckExact(PyTuple_GET_ITEM(o, 2))) {
    *v = (Vec){PyFloat_AS_DOUBLE(PyTuple_GET_ITEM(o, 0)), PyFloat_AS_DOUBLE(PyTuple_GET_ITEM(o, 1)),
               PyFloat_AS_DOUBLE(PyTuple_GET_ITEM(o, 2))};
    return true;
  }
  if (PyObject_CheckBuffer(o) && read_buffer_vec(o, v) == 1) {
    return true;
  }
  PyObject *seq = PySequence_Fast(o, "");
  if (seq == NULL) {
    PyErr_Clear();
    return false;
  }
  bool ok = PySequence_Fast_GET_SIZE(seq) == 3;
  if (ok) {
    PyObject **items = PySequence_Fast_ITEMS(seq);
    v->x = PyFloat_AsDouble(items[0]);
    v->y = PyFloat_AsDouble(items[1]);
    v->z = PyFloat_AsDouble(items[2]);
    if (PyErr_Occurred()) {
      PyErr_Clear();
      ok = false;
    }
  }
  Py_DECREF(seq);
  return ok;
}

static bool read_number(PyObject *o, double *x)
{
  *x = PyFloat_AsDouble(o);
  if (*x == -1.0 && PyErr_Occurred()) {
    PyErr_Clear();
    return false;
  }
  return true;
}

/* the six points of an interval; false when one is not 3 finite numbers */
static bool read_interval(PyObject *const *args, Vec *p)
{
  for (int i = 0; i < 6; i++) {
    if (!read_vec(args[i], &p[i]) || !finite3(p[i])) {
      return false;
    }
  }
  return true;
}

static bool non_negative(double x) { return isfinite(x) && x >= 0.0; }

static PyObject *not_implemented(void) { Py_RETURN_NOTIMPLEMENTED; }

/* ------------------------------------------------------------------------------------------ */
/* Python entry points */

/*
 * Where a class with __slots__ keeps field `name`: the offset of its member descriptor's object
 * (a writable T_OBJECT_EX slot, filled in straight as the class's own __init__ would), or -1
 * (another kind of attribute). False with an exception: the class has no such attribute.
 */
static bool slot_offset(PyObject *type, PyObject *name, Py_ssize_t *offset)
{
  PyObject *descriptor = PyObject_GetAttr(type, name);
  if (descriptor == NULL) {
    return false;
  }
  *offset = -1;
  if (Py_IS_TYPE(descriptor, &PyMemberDescr_Type)) {
    PyMemberDef *member = ((PyMemberDescrObject *)descriptor)->d_member;
    if (member->type == T_OBJECT_EX && !(member->flags & READONLY)) {
      *offset = member->offset;
    }
  }
  Py_DECREF(descriptor);
  return true;
}

static PyObject *py_bind(PyObject *self, PyObject *args)
{
  PyObject *type, *names, *members;
  if (!PyArg_ParseTuple(args, "O!O!O!", &PyType_Type, &type, &PyTuple_Type, &names,
                        &PyTuple_Type, &members)) {
    return NULL;
  }
  if (PyTuple_GET_SIZE(names) != 7 || PyTuple_GET_SIZE(members) != 3) {
    PyErr_SetString(PyExc_ValueError, "bind(type, its 7 field names, (side, knob_end, tip_end))");
    return NULL;
  }
  if (no_arguments == NULL && (no_arguments = PyTuple_New(0)) == NULL) {
    return NULL;
  }
  /* a class with __slots__: each field is a member descriptor holding an object at an offset */
  Py_ssize_t offsets[7];
  for (int i = 0; i < 7; i++) {
    if (!slot_offset(type, PyTuple_GET_ITEM(names, i), &offsets[i])) {
      return NULL;
    }
  }
  for (int i = 0; i < 7; i++) {
    slot_offsets[i] = offsets[0] < 0 ? -1 : offsets[i];
    if (offsets[i] < 0) {
      slot_offsets[0] = -1;
    }
  }
  Py_INCREF(type);
  Py_INCREF(names);
  Py_INCREF(members);
  Py_XSETREF(result_type, type);
  Py_XSETREF(result_fields, names);
  Py_XSETREF(features, members);
  Py_RETURN_NONE;
}

static PyObject *py_capsule(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  if (nargs != 9) {
    PyErr_SetString(PyExc_TypeError, "capsule() takes 9 arguments");
    return NULL;
  }
  Vec p[6];
  double rb, rt, dt, tau;
  if (!read_interval(args, p) || !read_number(args[6], &rb) || !read_number(args[7], &rt) ||
      !read_number(args[8], &dt) || !non_negative(rb) || !non_negative(rt) || !isfinite(dt) ||
      !(dt > 0.0)) {
    return not_implemented();
  }
  if (!capsule_tau(p, rb + rt, &tau)) {
    Py_RETURN_NONE;
  }
  return contact_at(tau, dt, p, rb, rt, rt, 0.0, 1.0, true, true, 0.0, 1.0);
}

/* the last profile seen and its pieces (the detector asks with one profile all the time) */
static struct {
  PyObject *profile;
  int count;
  double segments[MAX_SEGMENTS][4]; /* f0, f1, radius at f0, radius at f1 */
  double max_radius;
} profile_cache = {NULL, 0, {{0}}, 0.0};

/* 4 numbers from a sequence into out; false (an exception set) when it is not one */
static bool read_four(PyObject *o, double out[4])
{
  PyObject *seq = PySequence_Fast(o, "a profile piece must be 4 numbers");
  bool ok = seq != NULL && PySequence_Fast_GET_SIZE(seq) == 4;
  for (Py_ssize_t i = 0; ok && i < 4; i++) {
    out[i] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(seq, i));
    ok = !PyErr_Occurred();
  }
  Py_XDECREF(seq);
  if (!ok) {
    PyErr_Clear();
    PyErr_SetString(PyExc_TypeError, "a profile piece must be 4 numbers");
  }
  return ok;
}

static bool load_profile(PyObject *profile)
{
  if (profile == profile_cache.profile) {
    return true;
  }
  PyObject *segments = PyObject_CallMethod(profile, "segments", NULL);
  PyObject *max_radius = PyObject_GetAttrString(profile, "max_radius");
  PyObject *seq = segments ? PySequence_Fast(segments, "segments() must be a sequence") : NULL;
  bool ok = seq != NULL && max_radius != NULL;
  if (ok) {
    Py_ssize_t n = PySequence_Fast_GET_SIZE(seq);
    if (n < 1 || n > MAX_SEGMENTS) {
      PyErr_Format(PyExc_ValueError, "a bat profile needs 1 to %d pieces, got %zd",
                   MAX_SEGMENTS, n);
      ok = false;
    }
    for (Py_ssize_t i = 0; ok && i < n; i++) {
      ok = read_four(PySequence_Fast_GET_ITEM(seq, i), profile_cache.segments[i]);
    }
    if (ok) {
      profile_cache.max_radius = PyFloat_AsDouble(max_radius);
      ok = !PyErr_Occurred();
      profile_cache.count = (int)n;
    }
  }
  Py_XDECREF(segments);
  Py_XDECREF(max_radius);
  Py_XDECREF(seq);
  Py_XSETREF(profile_cache.profile, NULL);
  if (ok) {
    Py_INCREF(profile);
    profile_cache.profile = profile;
  }
  return ok;
}

/*
 * First contact of a ball with the cached profile's pieces over one interval (points p: b0,
 * b1, tip0, tip1, knob0, knob1): false when none; else its tau, the capsule's index and the
 * capsule's moving ends in piece (b0, b1, tip0, tip1, knob0, knob1).
 */
static bool profile_tau(const Vec *p, double rb, double *best_tau, int *best, Vec *piece)
{
  int count = profile_cache.count;
  if (count > 1 && !may_touch(p, rb + profile_cache.max_radius)) {
    return false;
  }
  bool have = false;
  for (int i = 0; i < count; i++) {
    const double *piece_of = profile_cache.segments[i];
    double f0 = piece_of[0], f1 = piece_of[1], tau;
    Vec capsule[6] = {p[0], p[1], v_lerp(p[4], p[2], f1), v_lerp(p[5], p[3], f1),
                      v_lerp(p[4], p[2], f0), v_lerp(p[5], p[3], f0)};
    if (cone_tau(capsule, rb + piece_of[2], piece_of[3] - piece_of[2], &tau) &&
        (!have || tau < *best_tau)) {
      have = true;
      *best_tau = tau;
      *best = i;
      memcpy(piece, capsule, sizeof capsule);
    }
  }
  return have;
}

/* the ImpactResult of profile_tau's contact */
static PyObject *profile_result(double tau, int best, double dt, const Vec *piece, double rb)
{
  const double *piece_of = profile_cache.segments[best];
  return contact_at(tau, dt, piece, rb, piece_of[2], piece_of[3], piece_of[0], piece_of[1],
                    best == 0, best == profile_cache.count - 1, profile_cache.segments[0][0],
                    profile_cache.segments[profile_cache.count - 1][1]);
}

static PyObject *py_profile(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  if (nargs != 9) {
    PyErr_SetString(PyExc_TypeError, "profile() takes 9 arguments");
    return NULL;
  }
  Vec p[6], piece[6];
  double rb, dt, tau = 0.0;
  int best = 0;
  if (!read_interval(args, p) || !read_number(args[6], &rb) || !read_number(args[8], &dt) ||
      !non_negative(rb) || !isfinite(dt) || !(dt > 0.0)) {
    return not_implemented();
  }
  if (!load_profile(args[7])) {
    return NULL;
  }
  if (!profile_tau(p, rb, &tau, &best, piece)) {
    Py_RETURN_NONE;
  }
  return profile_result(tau, best, dt, piece, rb);
}

/*
 * The gap (m) of a ball centre to the cached profile's pieces at one instant, less the ball's
 * radius; the fraction along knob-tip of the closest axis point in *fraction and the offset
 * from that point to the ball in *closest (core.toi.profile_gap; each operation in the order
 * of the Python it replaced, so the same bits).
 */
static double profile_gap_at(Vec ball, Vec knob, Vec tip, double ball_radius, double *fraction,
                             Vec *closest, Vec *axis_out)
{
  Vec axis = v_sub(tip, knob), offset = v_sub(ball, knob);
  double uu = v_dot(axis, axis), wu = v_dot(offset, axis), ww = v_dot(offset, offset);
  double along = uu > 0.0 ? wu / uu : 0.0;
  double best_gap = INFINITY, best_fraction = 0.0, best_radius = 0.0;
  bool best_cone = false;
  for (int i = 0; i < profile_cache.count; i++) {
    const double *piece = profile_cache.segments[i];
    double f0 = piece[0], f1 = piece[1], at = along, radius = piece[2];
    if (piece[3] != piece[2] && f1 > f0 && uu > 0.0) {
      /* a round cone: the nearest sphere slides past the perpendicular's foot (cone_closest),
         its radius growing by slope per unit of fraction */
      double slope = (piece[3] - piece[2]) / (f1 - f0);
      if (uu > slope * slope) {
        double across = sqrt(max_of(0.0, ww - along * wu));
        at = along + slope * across / sqrt(uu * (uu - slope * slope));
      } else {
        at = slope > 0.0 ? f1 : f0;
      }
    }
    double f = at < f0 ? f0 : (at > f1 ? f1 : at);
    if (piece[3] != piece[2] && f1 > f0) {
      radius += (piece[3] - piece[2]) * ((f - f0) / (f1 - f0));
    }
    /* |offset - f axis|, without building the vector */
    double gap = sqrt(max_of(0.0, ww - f * (2.0 * wu - f * uu))) - radius;
    if (gap < best_gap) {
      best_gap = gap;
      best_fraction = f;
      best_radius = radius;
      best_cone = piece[3] != piece[2] || f == f0 || f == f1; /* (or a piece's end sphere) */
    }
  }
  *fraction = best_fraction;
  if (closest != NULL) {
    *closest = v_sub(offset, v_scale(axis, best_fraction));
    *axis_out = axis;
    double first = profile_cache.segments[0][0];
    double last = profile_cache.segments[profile_cache.count - 1][1];
    double length = sqrt(v_dot(*closest, *closest));
    if (best_cone && first < best_fraction && best_fraction < last && length > 0.0 && uu > 0.0) {
      /* the spot on a taper or a piece's end sphere: the surface point's own place along the
         axis (as contact_at's) */
      double spot = best_fraction + best_radius * (v_dot(*closest, axis) / length) / uu;
      *fraction = min_of(last, max_of(first, spot));
    }
  }
  return best_gap - ball_radius;
}

/* a state on a linear sub-step: a + (b - a) s for ball, knob and tip (episodes' state) */
static double sub_step_gap(const Vec *p, double s, double ball_radius)
{
  double fraction;
  return profile_gap_at(v_lerp(p[0], p[1], s), v_lerp(p[2], p[3], s), v_lerp(p[4], p[5], s),
                        ball_radius, &fraction, NULL, NULL);
}

/*
 * profile_gap(ball, knob, tip, ball_radius, profile) -> (gap in m, negative when overlapping;
 * unit normal from the bat axis to the ball centre; fraction along knob-tip of the closest axis
 * point). TypeError: a point that is not 3 numbers, a radius that is not a number.
 */
static PyObject *py_profile_gap(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Vec ball, knob, tip, closest, axis;
  double ball_radius, fraction;
  if (nargs != 5) {
    PyErr_SetString(PyExc_TypeError, "profile_gap(ball, knob, tip, ball_radius, profile)");
    return NULL;
  }
  if (!read_vec(args[0], &ball) || !read_vec(args[1], &knob) || !read_vec(args[2], &tip) ||
      !read_number(args[3], &ball_radius)) {
    PyErr_SetString(PyExc_TypeError,
                    "profile_gap: ball, knob and tip must be 3 numbers, ball_radius a number");
    return NULL;
  }
  if (!load_profile(args[4])) {
    return NULL;
  }
  double gap = profile_gap_at(ball, knob, tip, ball_radius, &fraction, &closest, &axis);
  double length = sqrt(v_dot(closest, closest));
  Vec normal = length > 0.0 ? v_scale(closest, 1.0 / length)
                            : unit_normal(closest, axis, (Vec){0.0, 0.0, 0.0});
  PyObject *normal_tuple = vec_tuple(normal);
  if (normal_tuple == NULL) {
    return NULL;
  }
  return Py_BuildValue("(dNd)", gap, normal_tuple, fraction);
}

/*
 * lowest_gap(ball0, ball1, knob0, knob1, tip0, tip1, ball_radius, profile) -> s in [0, 1]:
 * where on a linear sub-step (each body from its first point to its second) the gap to the
 * profile is smallest, by golden-section search (40 steps), against both ends: the smallest
 * (gap, s) as Python's min orders the pairs (core.detector.episodes.lowest_gap). TypeError as
 * profile_gap.
 */
static PyObject *py_lowest_gap(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Vec p[6];
  double ball_radius;
  if (nargs != 8) {
    PyErr_SetString(PyExc_TypeError,
                    "lowest_gap(ball0, ball1, knob0, knob1, tip0, tip1, ball_radius, profile)");
    return NULL;
  }
  for (int i = 0; i < 6; i++) {
    if (!read_vec(args[i], &p[i])) {
      PyErr_SetString(PyExc_TypeError, "lowest_gap: every point must be 3 numbers");
      return NULL;
    }
  }
  if (!read_number(args[6], &ball_radius)) {
    PyErr_SetString(PyExc_TypeError, "lowest_gap: ball_radius must be a number");
    return NULL;
  }
  if (!load_profile(args[7])) {
    return NULL;
  }
  const double golden = (sqrt(5.0) - 1.0) / 2.0;
  double lo = 0.0, hi = 1.0;
  double x1 = hi - golden * (hi - lo), x2 = lo + golden * (hi - lo);
  double g1 = sub_step_gap(p, x1, ball_radius), g2 = sub_step_gap(p, x2, ball_radius);
  for (int i = 0; i < 40; i++) {
    if (g1 < g2) {
      hi = x2, x2 = x1, g2 = g1;
      x1 = hi - golden * (hi - lo);
      g1 = sub_step_gap(p, x1, ball_radius);
    } else {
      lo = x1, x1 = x2, g1 = g2;
      x2 = lo + golden * (hi - lo);
      g2 = sub_step_gap(p, x2, ball_radius);
    }
  }
  /* min((gap(0), 0), (gap(1), 1), (min(g1, g2), x1 if g1 < g2 else x2)): pairs by gap, then s */
  double gaps[3] = {sub_step_gap(p, 0.0, ball_radius), sub_step_gap(p, 1.0, ball_radius),
                    min_of(g1, g2)};
  double places[3] = {0.0, 1.0, g1 < g2 ? x1 : x2};
  int best = 0;
  for (int i = 1; i < 3; i++) {
    bool less = gaps[i] == gaps[best] ? places[i] < places[best] : gaps[i] < gaps[best];
    if (less) {
      best = i;
    }
  }
  return PyFloat_FromDouble(places[best]);
}

static PyObject *py_closest_offset(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Vec p[6];
  if (nargs != 6 || !read_interval(args, p)) {
    PyErr_SetString(PyExc_TypeError, "closest_offset() takes 6 points of 3 finite numbers");
    return NULL;
  }
  return vec_tuple(closest_offset(p));
}

/* one row of the batch: contact time in seconds, or NaN (no contact or a bad row) */
static double solve_row(const Vec *p, double rb, double rt, double dt)
{
  if (!finite_points(p, 6)) {
    return NAN;
  }
  if (!non_negative(rb) || !non_negative(rt) || !isfinite(rb + rt) || !isfinite(dt) ||
      !(dt > 0.0)) {
    return NAN;
  }
  double tau;
  if (!capsule_tau(p, rb + rt, &tau)) {
    return NAN;
  }
  return tau * dt;
}

/*
 * A contiguous float64 buffer of any length (writable if asked): its view (release it) and its
 * count of doubles; false with an exception (not such a buffer).
 */
static bool get_doubles(PyObject *o, Py_buffer *view, Py_ssize_t *count, const char *what,
                        bool writable)
{
  int flags = PyBUF_FORMAT | PyBUF_C_CONTIGUOUS | (writable ? PyBUF_WRITABLE : 0);
  if (PyObject_GetBuffer(o, view, flags) < 0) {
    return false;
  }
  if (view->itemsize != sizeof(double) || view->format == NULL ||
      strchr(view->format, 'd') == NULL) {
    PyErr_Format(PyExc_ValueError, "%s: expected a contiguous float64 array", what);
    PyBuffer_Release(view);
    return false;
  }
  *count = view->len / (Py_ssize_t)sizeof(double);
  return true;
}

/* a contiguous buffer of n items of one of the given struct formats (itemsize bytes), writable
 * if asked; false with a ValueError (numpy's own for a read-only array) */
static bool get_items(PyObject *o, Py_buffer *view, Py_ssize_t n, Py_ssize_t itemsize,
                      const char *formats, const char *what, bool writable)
{
  int flags = PyBUF_FORMAT | PyBUF_C_CONTIGUOUS | (writable ? PyBUF_WRITABLE : 0);
  if (PyObject_GetBuffer(o, view, flags) < 0) {
    return false;
  }
  if (view->itemsize != itemsize || view->format == NULL || strlen(view->format) != 1 ||
      strchr(formats, view->format[0]) == NULL || view->len != n * itemsize) {
    PyErr_Format(PyExc_ValueError, "%s: expected a contiguous array of %zd items", what, n);
    PyBuffer_Release(view);
    return false;
  }
  return true;
}

/* a C-contiguous buffer of `items` float64 values */
static bool get_buffer(PyObject *o, Py_buffer *view, Py_ssize_t items, bool writable)
{
  Py_ssize_t count;
  if (!get_doubles(o, view, &count, "a buffer", writable)) {
    return false;
  }
  if (count != items) {
    PyErr_Format(PyExc_ValueError, "expected a contiguous buffer of %zd float64 values", items);
    PyBuffer_Release(view);
    return false;
  }
  return true;
}

/* capsule_rows(b0, b1, e0, e1, s0, s1, ball_radius, bat_radius, dt, out, start, stop) */
static PyObject *py_capsule_rows(PyObject *self, PyObject *args)
{
  PyObject *objects[10];
  Py_buffer views[10];
  Py_ssize_t start, stop, n;
  if (!PyArg_ParseTuple(args, "OOOOOOOOOOnn", &objects[0], &objects[1], &objects[2],
                        &objects[3], &objects[4], &objects[5], &objects[6], &objects[7],
                        &objects[8], &objects[9], &start, &stop)) {
    return NULL;
  }
  n = PyObject_Length(objects[9]);
  if (n < 0) {
    return NULL;
  }
  int got = 0;
  while (got < 10 && get_buffer(objects[got], &views[got], got < 6 ? 3 * n : n, got == 9)) {
    got++;
  }
  if (got == 10 && !(0 <= start && start <= stop && stop <= n)) {
    PyErr_SetString(PyExc_ValueError, "rows out of range");
  } else if (got == 10) {
    const double *points[6], *rb = views[6].buf, *rt = views[7].buf, *dt = views[8].buf;
    double *out = views[9].buf;
    for (int k = 0; k < 6; k++) {
      points[k] = views[k].buf;
    }
    Py_BEGIN_ALLOW_THREADS
    for (Py_ssize_t i = start; i < stop; i++) {
      Vec p[6];
      for (int k = 0; k < 6; k++) {
        p[k] = (Vec){points[k][3 * i], points[k][3 * i + 1], points[k][3 * i + 2]};
      }
      out[i] = solve_row(p, rb[i], rt[i], dt[i]);
    }
    Py_END_ALLOW_THREADS
  }
  for (int i = 0; i < got; i++) {
    PyBuffer_Release(&views[i]);
  }
  if (PyErr_Occurred()) {
    return NULL;
  }
  Py_RETURN_NONE;
}

/* ------------------------------------------------------------------------------------------ */
/* predictions: the forecasts of ball and bat over a horizon, and their first contact */

/* the ball with constant acceleration from t0 on */
typedef struct {
  double t0;
  Vec p, v, a;
} BallPath;

/*
 * The bat: extrapolated (a pivot with constant acceleration turning about a fixed axis with
 * constant angular acceleration) or planned (poses at increasing times: position LERP,
 * orientation SLERP; knob and tip at body-frame offsets).
 */
typedef struct {
  bool planned;
  double t0, rate, rate_change;
  Vec pivot, pivot_velocity, pivot_acceleration, knob_arm, tip_arm, axis;
  Py_ssize_t n;
  const double *times, *positions, *quaternions;
  Vec knob_offset, tip_offset;
} BatPath;

static inline double v_norm(Vec a) { return sqrt(v_dot(a, a)); }

static Vec ball_at(const BallPath *b, double t)
{
  double tau = t - b->t0, half = 0.5 * tau * tau;
  return (Vec){b->p.x + (b->v.x * tau + b->a.x * half), b->p.y + (b->v.y * tau + b->a.y * half),
               b->p.z + (b->v.z * tau + b->a.z * half)};
}

static Vec ball_velocity_at(const BallPath *b, double t)
{
  return v_advance(b->v, b->a, t - b->t0);
}

/* Rodrigues' rotation of vector about the unit axis by angle (rad), as geometry.turn_about */
static Vec turn_about(Vec vector, Vec axis, double angle)
{
  if (angle == 0.0) {
    return vector;
  }
  double cosine = cos(angle), sine = sin(angle);
  double along = v_dot(axis, vector) * (1.0 - cosine);
  Vec across = v_cross(axis, vector);
  return (Vec){vector.x * cosine + across.x * sine + axis.x * along,
               vector.y * cosine + across.y * sine + axis.y * along,
               vector.z * cosine + across.z * sine + axis.z * along};
}

static inline double dot4(const double *a, const double *b)
{
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
}

/* unit quaternions (x, y, z, w) interpolated along the shorter arc, as geometry.slerp_quaternions */
static void slerp(const double *q0, const double *q1_in, double s, double *out)
{
  double q1[4] = {q1_in[0], q1_in[1], q1_in[2], q1_in[3]}, q[4];
  double cosine = dot4(q0, q1);
  if (cosine < 0.0) {
    for (int i = 0; i < 4; i++) {
      q1[i] = -q1[i];
    }
    cosine = -cosine;
  }
  if (cosine > 1.0 - 1e-12) {
    for (int i = 0; i < 4; i++) {
      q[i] = q0[i] + (q1[i] - q0[i]) * s;
    }
  } else {
    double angle = acos(cosine), sin_angle = sin(angle);
    double w0 = sin((1.0 - s) * angle) / sin_angle, w1 = sin(s * angle) / sin_angle;
    for (int i = 0; i < 4; i++) {
      q[i] = w0 * q0[i] + w1 * q1[i];
    }
  }
  double length = sqrt(dot4(q, q));
  for (int i = 0; i < 4; i++) {
    out[i] = q[i] / length;
  }
}

/* where the body-frame offset is for the pose (position, unit quaternion q), as geometry.pose_point */
static Vec pose_point(Vec position, const double *q, Vec v)
{
  double x = q[0], y = q[1], z = q[2], w = q[3];
  double cx = y * v.z - z * v.y, cy = z * v.x - x * v.z, cz = x * v.y - y * v.x;
  Vec arm = {v.x + 2.0 * (w * cx + y * cz - z * cy), v.y + 2.0 * (w * cy + z * cx - x * cz),
             v.z + 2.0 * (w * cz + x * cy - y * cx)};
  return (Vec){position.x + arm.x, position.y + arm.y, position.z + arm.z};
}

/* bisect.bisect_right and bisect_left on the plan's times */
static Py_ssize_t bisect_right(const double *x, Py_ssize_t n, double t)
{
  Py_ssize_t lo = 0, hi = n;
  while (lo < hi) {
    Py_ssize_t mid = (lo + hi) / 2;
    if (t < x[mid]) {
      hi = mid;
    } else {
      lo = mid + 1;
    }
  }
  return lo;
}

static Py_ssize_t bisect_left(const double *x, Py_ssize_t n, double t)
{
  Py_ssize_t lo = 0, hi = n;
  while (lo < hi) {
    Py_ssize_t mid = (lo + hi) / 2;
    if (x[mid] < t) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return lo;
}

static inline Vec row3(const double *x, Py_ssize_t k) { return (Vec){x[3 * k], x[3 * k + 1], x[3 * k + 2]}; }

/* the plan's pose segment for t (the first or last one outside) and the fraction along it */
static Py_ssize_t plan_segment(const BatPath *b, double t, double *s)
{
  Py_ssize_t k = bisect_right(b->times, b->n, t) - 1;
  k = k < b->n - 2 ? k : b->n - 2;
  k = k > 0 ? k : 0;
  *s = b->n < 2 ? 0.0 : (t - b->times[k]) / (b->times[k + 1] - b->times[k]);
  return k;
}

/* the pivot (the pose origin of a plan) at t */
static Vec pivot_at(const BatPath *b, double t)
{
  if (!b->planned) {
    double tau = t - b->t0, half = 0.5 * tau * tau;
    Vec p = b->pivot, v = b->pivot_velocity, a = b->pivot_acceleration;
    return (Vec){p.x + (v.x * tau + a.x * half), p.y + (v.y * tau + a.y * half),
                 p.z + (v.z * tau + a.z * half)};
  }
  if (b->n == 1) {
    return row3(b->positions, 0);
  }
  double s;
  Py_ssize_t k = plan_segment(b, t, &s);
  return v_lerp(row3(b->positions, k), row3(b->positions, k + 1), s);
}

/* knob and tip at t */
static void bat_at(const BatPath *b, double t, Vec *knob, Vec *tip)
{
  if (!b->planned) {
    Vec pivot = pivot_at(b, t);
    double tau = t - b->t0;
    double angle = b->rate * tau + 0.5 * b->rate_change * tau * tau;
    Vec k = turn_about(b->knob_arm, b->axis, angle), e = turn_about(b->tip_arm, b->axis, angle);
    *knob = (Vec){pivot.x + k.x, pivot.y + k.y, pivot.z + k.z};
    *tip = (Vec){pivot.x + e.x, pivot.y + e.y, pivot.z + e.z};
    return;
  }
  double s, q[4];
  Py_ssize_t k = plan_segment(b, t, &s);
  Vec origin = row3(b->positions, k);
  if (b->n == 1) {
    memcpy(q, b->quaternions, sizeof q);
  } else {
    origin = v_lerp(origin, row3(b->positions, k + 1), s);
    slerp(b->quaternions + 4 * k, b->quaternions + 4 * (k + 1), s, q);
  }
  *knob = pose_point(origin, q, b->knob_offset);
  *tip = pose_point(origin, q, b->tip_offset);
}

/* the farthest any bat axis point is from the pivot (m) */
static double bat_reach(const BatPath *b)
{
  return b->planned ? max_of(v_norm(b->knob_offset), v_norm(b->tip_offset))
                    : max_of(v_norm(b->knob_arm), v_norm(b->tip_arm));
}

/* the largest turning rate (rad/s) over [ta, tb] (of a plan: between poses overlapping it) */
static double turn_rate_bound(const BatPath *b, double ta, double tb)
{
  if (!b->planned) {
    return max_of(fabs(b->rate + b->rate_change * (ta - b->t0)),
                  fabs(b->rate + b->rate_change * (tb - b->t0)));
  }
  double worst = 0.0;
  Py_ssize_t first = bisect_right(b->times, b->n, ta) - 1;
  Py_ssize_t stop = bisect_right(b->times, b->n, tb); /* index(tb) + 1 */
  first = first > 0 ? first : 0;
  stop = stop < b->n - 1 ? stop : b->n - 1;
  for (Py_ssize_t k = first; k < stop; k++) {
    double angle = 2.0 * acos(min_of(1.0, fabs(dot4(b->quaternions + 4 * k,
                                                     b->quaternions + 4 * (k + 1)))));
    worst = max_of(worst, angle / (b->times[k + 1] - b->times[k]));
  }
  return worst;
}

/*
 * A bound (m) on how far the pivot moves from where it is at ta, up to tb: speed and
 * acceleration for an extrapolated bat; the length of the pose origin's path for a plan.
 */
static double pivot_travel(const BatPath *b, double ta, double tb)
{
  double h = tb - ta;
  if (!b->planned) {
    double speed = v_norm(v_advance(b->pivot_velocity, b->pivot_acceleration, ta - b->t0));
    return speed * h + 0.5 * v_norm(b->pivot_acceleration) * h * h;
  }
  Py_ssize_t first = bisect_right(b->times, b->n, ta), end = bisect_left(b->times, b->n, tb);
  Vec previous = pivot_at(b, ta);
  double length = 0.0;
  for (Py_ssize_t k = first; k < end; k++) {
    Vec next = row3(b->positions, k);
    length += v_norm(v_sub(next, previous));
    previous = next;
  }
  return length + v_norm(v_sub(pivot_at(b, tb), previous));
}

/* what a search ended with */
typedef enum { SEARCH_NONE, SEARCH_FOUND, SEARCH_BAD } Search;

/*
 * First contact in the coarse step [ta, tb], solved on chord sub-steps short enough that the
 * ball's parabola (|a| h^2 / 8) and the bat's turn (reach (w h)^2 / 8) stay within tolerance of
 * their chords. SEARCH_BAD: the forecasts left finite numbers or the step has no length.
 */
static Search first_in_step(const BallPath *ball, const BatPath *bat, double ta, double tb,
                            double rb, double tolerance, double ball_accel, double *t_hit,
                            double *tau_hit, double *dt_hit, int *best, Vec *piece)
{
  double h = tb - ta;
  double rate = turn_rate_bound(bat, ta, tb);
  double per_step = sqrt(8.0 * tolerance / max_of(ball_accel, 1e-12));
  if (rate > 0.0) {
    per_step = min_of(per_step, sqrt(8.0 * tolerance / bat_reach(bat)) / rate);
  }
  double steps = ceil(h / per_step);
  if (!(steps <= 1e7)) {
    return SEARCH_BAD;
  }
  long n = steps >= 1.0 ? (long)steps : 1;
  double previous_t = ta;
  Vec p[6];
  p[0] = ball_at(ball, ta);
  bat_at(bat, ta, &p[4], &p[2]);
  for (long j = 1; j <= n; j++) {
    double t = j == n ? tb : ta + h * (double)j / (double)n;
    p[1] = ball_at(ball, t);
    bat_at(bat, t, &p[5], &p[3]);
    double dt = t - previous_t;
    if (!finite_points(p, 6)) {
      return SEARCH_BAD;
    }
    if (!(dt > 0.0) || !isfinite(dt)) {
      return SEARCH_BAD;
    }
    double tau;
    if (profile_tau(p, rb, &tau, best, piece)) {
      *tau_hit = tau;
      *dt_hit = dt;
      *t_hit = previous_t + tau * dt;
      return SEARCH_FOUND;
    }
    previous_t = t;
    p[0] = p[1];
    p[2] = p[3];
    p[4] = p[5];
  }
  return SEARCH_NONE;
}

/* n floats from a sequence into x; false with an exception set (a wrong count: error) */
static bool read_floats_or(PyObject *o, double *x, Py_ssize_t n, const char *what,
                           PyObject *error)
{
  PyObject *seq = PySequence_Fast(o, what);
  if (seq == NULL) {
    return false;
  }
  bool ok = PySequence_Fast_GET_SIZE(seq) == n;
  for (Py_ssize_t i = 0; ok && i < n; i++) {
    x[i] = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(seq, i));
    ok = !PyErr_Occurred();
  }
  Py_DECREF(seq);
  if (!ok && !PyErr_Occurred()) {
    PyErr_Format(error, "%s: expected %zd numbers", what, n);
  }
  return ok;
}

static bool read_floats(PyObject *o, double *x, Py_ssize_t n, const char *what)
{
  return read_floats_or(o, x, n, what, PyExc_TypeError);
}

/* (t0, position, velocity, acceleration): 10 numbers */
static bool read_ball(PyObject *o, BallPath *b)
{
  double x[10];
  if (!read_floats(o, x, 10, "ball forecast (t0, position, velocity, acceleration)")) {
    return false;
  }
  *b = (BallPath){x[0], {x[1], x[2], x[3]}, {x[4], x[5], x[6]}, {x[7], x[8], x[9]}};
  return true;
}

/* the plan's three buffers, held while its BatPath is in use */
typedef struct {
  Py_buffer views[3];
  int held;
} PlanViews;

static void release_plan(PlanViews *views)
{
  for (int i = 0; i < views->held; i++) {
    PyBuffer_Release(&views->views[i]);
  }
  views->held = 0;
}

/*
 * An extrapolated bat (t0, pivot, pivot_velocity, pivot_acceleration, knob_arm, tip_arm, axis,
 * rate, rate_change: 21 numbers) or a plan (times (n,), positions (n, 3), quaternions (n, 4)
 * as contiguous float64 buffers, knob_offset, tip_offset)
 */
static bool read_bat(PyObject *o, BatPath *b, PlanViews *views)
{
  views->held = 0;
  if (!PyTuple_Check(o)) {
    PyErr_SetString(PyExc_TypeError, "a bat forecast must be a tuple");
    return false;
  }
  memset(b, 0, sizeof *b);
  if (PyTuple_GET_SIZE(o) != 5) {
    double x[21];
    if (!read_floats(o, x, 21, "bat forecast (t0, pivot, pivot_velocity, "
                     "pivot_acceleration, knob_arm, tip_arm, axis, rate, rate_change)")) {
      return false;
    }
    b->t0 = x[0];
    b->pivot = (Vec){x[1], x[2], x[3]};
    b->pivot_velocity = (Vec){x[4], x[5], x[6]};
    b->pivot_acceleration = (Vec){x[7], x[8], x[9]};
    b->knob_arm = (Vec){x[10], x[11], x[12]};
    b->tip_arm = (Vec){x[13], x[14], x[15]};
    b->axis = (Vec){x[16], x[17], x[18]};
    b->rate = x[19];
    b->rate_change = x[20];
    return true;
  }
  b->planned = true;
  Py_ssize_t n = PyObject_Length(PyTuple_GET_ITEM(o, 0));
  if (n < 0) {
    return false;
  }
  Py_ssize_t widths[3] = {1, 3, 4};
  while (views->held < 3) {
    if (!get_buffer(PyTuple_GET_ITEM(o, views->held), &views->views[views->held],
                    widths[views->held] * n, false)) {
      release_plan(views);
      return false;
    }
    views->held++;
  }
  double offsets[6];
  if (!read_floats(PyTuple_GET_ITEM(o, 3), offsets, 3, "knob_offset") ||
      !read_floats(PyTuple_GET_ITEM(o, 4), offsets + 3, 3, "tip_offset")) {
    release_plan(views);
    return false;
  }
  b->n = n;
  b->times = views->views[0].buf;
  b->positions = views->views[1].buf;
  b->quaternions = views->views[2].buf;
  b->knob_offset = (Vec){offsets[0], offsets[1], offsets[2]};
  b->tip_offset = (Vec){offsets[3], offsets[4], offsets[5]};
  return true;
}

/*
 * The first contact of the forecasts within [t_start, t_start + horizon] (a plan: the part it
 * covers), scanned in coarse steps: a step is skipped when the ball stays farther from the
 * bat's pivot than the bat reaches (plus the radii, the loaded profile's, and what both can
 * travel in the step), else solved on chord sub-steps (first_in_step, whose outputs it sets).
 */
static Search search_first(const BallPath *ball, const BatPath *bat, double t_start,
                           double horizon, double rb, double tolerance, double coarse,
                           double *t_hit, double *tau, double *dt, int *best, Vec *piece)
{
  double end = t_start + horizon;
  Search found = SEARCH_NONE;
  if (!bat->planned || bat->n > 0) {
    if (bat->planned) {
      t_start = max_of(t_start, bat->times[0]);
      end = min_of(end, bat->times[bat->n - 1]);
    }
    double reach = bat_reach(bat) + rb + profile_cache.max_radius;
    double ball_accel = v_norm(ball->a);
    for (double ta = t_start; ta < end && found == SEARCH_NONE;) {
      double tb = min_of(end, ta + coarse), h = tb - ta;
      /* the largest distance either body can move from its position at ta within the step */
      double travel = v_norm(ball_velocity_at(ball, ta)) * h + 0.5 * ball_accel * h * h +
                      pivot_travel(bat, ta, tb) + 1e-9;
      double gap = v_norm(v_sub(ball_at(ball, ta), pivot_at(bat, ta)));
      if (!(gap > reach + travel)) {
        found = first_in_step(ball, bat, ta, tb, rb, tolerance, ball_accel, t_hit, tau, dt,
                              best, piece);
      }
      ta = tb;
    }
  }
  return found;
}

/*
 * first_contact(ball, bat, t_start, horizon, ball_radius, profile, tolerance, coarse_step)
 * -> (t, ImpactResult), None, or NotImplemented (the forecasts left finite numbers)
 */
static PyObject *py_first_contact(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  if (nargs != 8) {
    PyErr_SetString(PyExc_TypeError, "first_contact() takes 8 arguments");
    return NULL;
  }
  BallPath ball;
  BatPath bat;
  PlanViews views;
  double t_start, horizon, rb, tolerance, coarse;
  if (!read_ball(args[0], &ball) || !read_number(args[2], &t_start) ||
      !read_number(args[3], &horizon) || !read_number(args[4], &rb) ||
      !read_number(args[6], &tolerance) || !read_number(args[7], &coarse)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "first_contact(): numbers expected");
    }
    return NULL;
  }
  if (!non_negative(rb) || !(tolerance > 0.0) || !(coarse > 0.0) || !isfinite(t_start) ||
      !isfinite(horizon)) {
    PyErr_SetString(PyExc_ValueError, "first_contact(): ball_radius >= 0, tolerance > 0, "
                    "coarse_step > 0 and finite times expected");
    return NULL;
  }
  if (!load_profile(args[5]) || !read_bat(args[1], &bat, &views)) {
    return NULL;
  }
  double t_hit = 0.0, tau = 0.0, dt = 0.0;
  int best = 0;
  Vec piece[6];
  Search found = search_first(&ball, &bat, t_start, horizon, rb, tolerance, coarse, &t_hit,
                              &tau, &dt, &best, piece);
  release_plan(&views);
  if (found == SEARCH_BAD) {
    return not_implemented();
  }
  if (found == SEARCH_NONE) {
    Py_RETURN_NONE;
  }
  PyObject *hit = profile_result(tau, best, dt, piece, rb);
  if (hit == NULL) {
    return NULL;
  }
  return Py_BuildValue("(dN)", t_hit, hit);
}

/* forecast(ball or None, bat or None, t) -> (ball centre, ball velocity, knob, tip, pivot) */
static PyObject *py_forecast(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  double t;
  if (nargs != 3 || !read_number(args[2], &t)) {
    PyErr_SetString(PyExc_TypeError, "forecast(ball or None, bat or None, t)");
    return NULL;
  }
  BallPath ball;
  BatPath bat;
  PlanViews views;
  bool have_ball = args[0] != Py_None, have_bat = args[1] != Py_None;
  Vec values[5] = {{0.0, 0.0, 0.0}};
  if (have_ball) {
    if (!read_ball(args[0], &ball)) {
      return NULL;
    }
    values[0] = ball_at(&ball, t);
    values[1] = ball_velocity_at(&ball, t);
  }
  if (have_bat) {
    if (!read_bat(args[1], &bat, &views)) {
      return NULL;
    }
    if (bat.planned && bat.n == 0) {
      release_plan(&views);
      PyErr_SetString(PyExc_ValueError, "an empty plan has no pose");
      return NULL;
    }
    bat_at(&bat, t, &values[2], &values[3]);
    values[4] = pivot_at(&bat, t);
    release_plan(&views);
  }
  PyObject *result = PyTuple_New(5);
  for (int i = 0; result != NULL && i < 5; i++) {
    PyObject *item = (i < 2 ? have_ball : have_bat) ? vec_tuple(values[i]) : Py_NewRef(Py_None);
    if (item == NULL) {
      Py_CLEAR(result);
      break;
    }
    PyTuple_SET_ITEM(result, i, item);
  }
  return result;
}

/* bat_bounds(bat, ta, tb) -> (pivot travel bound m, turning rate bound rad/s, reach m) */
static PyObject *py_bat_bounds(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  double ta, tb;
  BatPath bat;
  PlanViews views;
  if (nargs != 3 || !read_number(args[1], &ta) || !read_number(args[2], &tb)) {
    PyErr_SetString(PyExc_TypeError, "bat_bounds(bat, ta, tb)");
    return NULL;
  }
  if (!read_bat(args[0], &bat, &views)) {
    return NULL;
  }
  if (bat.planned && bat.n == 0) {
    release_plan(&views);
    PyErr_SetString(PyExc_ValueError, "an empty plan has no pose");
    return NULL;
  }
  double travel = pivot_travel(&bat, ta, tb), rate = turn_rate_bound(&bat, ta, tb);
  double reach = bat_reach(&bat);
  release_plan(&views);
  return Py_BuildValue("(ddd)", travel, rate, reach);
}

/* ------------------------------------------------------------------------------------------ */
/* the building blocks, exposed for the tests */

static bool read_coefficients(PyObject *o, double *c, Py_ssize_t count)
{
  return read_floats_or(o, c, count, "coefficients", PyExc_ValueError);
}

/* count floats as a new list, or a new tuple */
static PyObject *float_sequence(const double *x, int count, bool tuple)
{
  PyObject *sequence = tuple ? PyTuple_New(count) : PyList_New(count);
  for (int i = 0; sequence != NULL && i < count; i++) {
    PyObject *item = PyFloat_FromDouble(x[i]);
    if (item == NULL) {
      Py_CLEAR(sequence);
      break;
    }
    if (tuple) {
      PyTuple_SET_ITEM(sequence, i, item);
    } else {
      PyList_SET_ITEM(sequence, i, item);
    }
  }
  return sequence;
}

static PyObject *float_list(const double *x, int count) { return float_sequence(x, count, false); }

/* rows of m floats each (row-major), as a list of tuples (or of lists) */
static PyObject *float_rows(const double *y, Py_ssize_t rows, Py_ssize_t m, bool tuples)
{
  PyObject *list = PyList_New(rows);
  for (Py_ssize_t i = 0; list != NULL && i < rows; i++) {
    PyObject *row = float_sequence(y + i * m, (int)m, tuples);
    if (row == NULL) {
      Py_CLEAR(list);
      break;
    }
    PyList_SET_ITEM(list, i, row);
  }
  return list;
}

static PyObject *py_quadratic_roots(PyObject *self, PyObject *args)
{
  double a, b, c, roots[2];
  if (!PyArg_ParseTuple(args, "ddd", &a, &b, &c)) {
    return NULL;
  }
  return float_list(roots, quadratic_roots(a, b, c, roots));
}

static PyObject *py_bracketed_root(PyObject *self, PyObject *args)
{
  PyObject *o;
  int order;
  double c[5], lo, hi, f_lo;
  if (!PyArg_ParseTuple(args, "Oiddd", &o, &order, &lo, &hi, &f_lo) ||
      !read_coefficients(o, c, 5)) {
    return NULL;
  }
  return PyFloat_FromDouble(bracketed_root(c, order != 0, lo, hi, f_lo));
}

static PyObject *py_critical_points(PyObject *self, PyObject *o)
{
  double c[5], out[3];
  if (!read_coefficients(o, c, 5)) {
    return NULL;
  }
  return float_list(out, critical_points(c, out));
}

static PyObject *py_touch_candidates(PyObject *self, PyObject *args)
{
  PyObject *o, *p;
  double c[5], slack_poly[5], scale, tau, found[5];
  if (!PyArg_ParseTuple(args, "OdO", &o, &scale, &p) || !read_coefficients(o, c, 5) ||
      !read_coefficients(p, slack_poly, 5)) {
    return NULL;
  }
  Candidates it = {0};
  Slack slack = {scale, slack_poly};
  int count = 0;
  while (count < 5 && next_candidate(c, slack, &it, &tau)) {
    found[count++] = tau;
  }
  return float_list(found, count);
}

static PyObject *py_quadratic_entry(PyObject *self, PyObject *args)
{
  double a, b, c, slack, tau;
  if (!PyArg_ParseTuple(args, "dddd", &a, &b, &c, &slack)) {
    return NULL;
  }
  if (!quadratic_entry(a, b, c, slack, &tau)) {
    Py_RETURN_NONE;
  }
  return PyFloat_FromDouble(tau);
}

/* (w0, w1, u0, u1) as given (scale 1) */
static bool read_scaled(PyObject *const *args, Scaled *s)
{
  Vec v[4];
  for (int i = 0; i < 4; i++) {
    if (!read_vec(args[i], &v[i])) {
      PyErr_SetString(PyExc_TypeError, "w0, w1, u0, u1 must be 3 numbers each");
      return false;
    }
  }
  *s = (Scaled){v[0], v[1], v[2], v[3], 1.0};
  return true;
}

static PyObject *py_cap_quadratics(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Scaled s;
  double rr, caps[2][3];
  if (nargs != 5 || !read_scaled(args, &s) || !read_number(args[4], &rr)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "cap_quadratics(w0, w1, u0, u1, rr)");
    }
    return NULL;
  }
  cap_quadratics(&s, rr, rr, caps);
  return Py_BuildValue("((ddd)(ddd))", caps[0][0], caps[0][1], caps[0][2], caps[1][0],
                       caps[1][1], caps[1][2]);
}

static PyObject *py_side_quartic(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Scaled s;
  double rr, q[5], uu[5], wu[5];
  if (nargs != 5 || !read_scaled(args, &s) || !read_number(args[4], &rr)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "side_quartic(w0, w1, u0, u1, rr)");
    }
    return NULL;
  }
  side_quartic(&s, rr, 0.0, 0.0, q, uu, wu);
  return Py_BuildValue("((ddddd)(ddd)(ddd))", q[0], q[1], q[2], q[3], q[4], uu[0], uu[1],
                       uu[2], wu[0], wu[1], wu[2]);
}

/* ------------------------------------------------------------------------------------------ */
/* least-squares polynomial fits (the velocity and prediction fits of core.detector.kinematics) */

#define MAX_FIT_COMPONENTS 16
#define MAX_FIT_DEGREE 15
#define FIT_RANK_TOLERANCE 1e-13 /* |R_jj| / max |R_ii| below which a fit is left to LAPACK */

/*
 * Least squares of rows y (n x m, row-major) on the powers 0..p-1 of x (n values): Householder
 * QR of the Vandermonde matrix, applied to y as it goes, then back substitution. a (n x p) and
 * y are overwritten; the p x m coefficients go to c. False when the matrix is (numerically)
 * rank deficient.
 */
static inline __attribute__((always_inline)) bool householder_steps(
    const double *x, Py_ssize_t n, int p, double *a, double *y, int m, double *c)
{
  for (Py_ssize_t i = 0; i < n; i++) {
    double power = 1.0;
    for (int j = 0; j < p; j++) {
      a[i * p + j] = power;
      power *= x[i];
    }
  }
  double largest = 0.0;
  for (int j = 0; j < p; j++) {
    double below = 0.0; /* the squares below the diagonal */
    for (Py_ssize_t i = j + 1; i < n; i++) {
      below += a[i * p + j] * a[i * p + j];
    }
    double norm = sqrt(a[j * p + j] * a[j * p + j] + below);
    if (norm == 0.0) {
      return false;
    }
    double alpha = a[j * p + j] > 0.0 ? -norm : norm;
    /* the reflector v: column j from the diagonal down, with v_j = a_jj - alpha */
    double vj = a[j * p + j] - alpha;
    double vv = vj * vj + below;
    if (vv > 0.0) {
      /* the columns right of j in a, then y's: each one's sum in the order of its rows (so
       * the result is that of one column at a time), the rows walked contiguously */
      double sa[MAX_FIT_DEGREE + 1], sy[MAX_FIT_COMPONENTS]; /* a's columns, y's */
      int right = p - j - 1;
      for (int k = 0; k < right; k++) {
        sa[k] = vj * a[j * p + j + 1 + k];
      }
      for (int k = 0; k < m; k++) {
        sy[k] = vj * y[j * m + k];
      }
      for (Py_ssize_t i = j + 1; i < n; i++) {
        double v = a[i * p + j];
        const double *ra = a + i * p + j + 1, *ry = y + i * m;
        for (int k = 0; k < right; k++) {
          sa[k] += v * ra[k];
        }
        for (int k = 0; k < m; k++) {
          sy[k] += v * ry[k];
        }
      }
      for (int k = 0; k < right; k++) {
        sa[k] = 2.0 * sa[k] / vv;
      }
      for (int k = 0; k < m; k++) {
        sy[k] = 2.0 * sy[k] / vv;
      }
      for (int k = 0; k < right; k++) {
        a[j * p + j + 1 + k] -= sa[k] * vj;
      }
      for (int k = 0; k < m; k++) {
        y[j * m + k] -= sy[k] * vj;
      }
      for (Py_ssize_t i = j + 1; i < n; i++) {
        double v = a[i * p + j];
        double *ra = a + i * p + j + 1, *ry = y + i * m;
        for (int k = 0; k < right; k++) {
          ra[k] -= sa[k] * v;
        }
        for (int k = 0; k < m; k++) {
          ry[k] -= sy[k] * v;
        }
      }
    }
    a[j * p + j] = alpha;
    largest = max_of(largest, fabs(alpha));
  }
  for (int j = 0; j < p; j++) {
    if (!(fabs(a[j * p + j]) > FIT_RANK_TOLERANCE * largest)) {
      return false;
    }
  }
  for (int k = 0; k < m; k++) {
    for (int j = p - 1; j >= 0; j--) {
      double s = y[j * m + k];
      for (int i = j + 1; i < p; i++) {
        s -= a[j * p + i] * c[i * m + k];
      }
      c[j * m + k] = s / a[j * p + j];
    }
  }
  return true;
}

/*
 * householder_steps, with the forecasts' shapes (the ball's parabola in 3 coordinates, the bat's
 * cubic in its 10 components) as constants, so the compiler unrolls the loops over the columns:
 * the same operations in the same order on every element, so the same bits
 */
static bool householder_fit(const double *x, Py_ssize_t n, int p, double *a, double *y, int m,
                            double *c)
{
  if (p == 3 && m == 3) {
    return householder_steps(x, n, 3, a, y, 3, c);
  }
  if (p == 4 && m == 10) {
    return householder_steps(x, n, 4, a, y, 10, c);
  }
  return householder_steps(x, n, p, a, y, m, c);
}

/*
 * polyfit(times, rows, t, degree) -> (coefficients: degree + 1 lists of m, span) or
 * NotImplemented (rank deficient: the caller asks LAPACK). The polynomial is in
 * x = (time - t) / span, span = max(t - times[0], 1e-9); the degree drops to n - 1.
 */
static PyObject *py_polyfit(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  double t;
  long degree_arg;
  if (nargs != 4 || !read_number(args[2], &t) ||
      ((degree_arg = PyLong_AsLong(args[3])) == -1 && PyErr_Occurred())) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "polyfit(times, rows, t, degree)");
    }
    return NULL;
  }
  PyObject *times = PySequence_Fast(args[0], "times must be a sequence");
  PyObject *rows = times ? PySequence_Fast(args[1], "rows must be a sequence") : NULL;
  PyObject *result = NULL;
  double *memory = NULL;
  if (rows == NULL) {
    goto done;
  }
  Py_ssize_t n = PySequence_Fast_GET_SIZE(times);
  if (n < 1 || PySequence_Fast_GET_SIZE(rows) != n || degree_arg < 0) {
    PyErr_SetString(PyExc_ValueError, "polyfit: as many rows as times (at least one), degree >= 0");
    goto done;
  }
  PyObject *first_row = PySequence_Fast(PySequence_Fast_GET_ITEM(rows, 0), "a row");
  if (first_row == NULL) {
    goto done;
  }
  Py_ssize_t m = PySequence_Fast_GET_SIZE(first_row);
  Py_DECREF(first_row);
  int p = (int)((degree_arg < n - 1 ? degree_arg : n - 1) + 1);
  if (m < 1 || m > MAX_FIT_COMPONENTS || p > MAX_FIT_DEGREE + 1) {
    PyErr_Format(PyExc_ValueError, "polyfit: 1 to %d components and degree <= %d",
                 MAX_FIT_COMPONENTS, MAX_FIT_DEGREE);
    goto done;
  }
  memory = PyMem_Malloc(sizeof(double) * (size_t)(n * (1 + p + m) + p * m));
  if (memory == NULL) {
    PyErr_NoMemory();
    goto done;
  }
  double *x = memory, *a = x + n, *y = a + n * p, *c = y + n * m;
  double t_first = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(times, 0));
  double span = max_of(t - t_first, 1e-9);
  for (Py_ssize_t i = 0; i < n && !PyErr_Occurred(); i++) {
    x[i] = (PyFloat_AsDouble(PySequence_Fast_GET_ITEM(times, i)) - t) / span;
    if (!read_floats(PySequence_Fast_GET_ITEM(rows, i), y + i * m, m, "a row of the fit")) {
      break;
    }
  }
  if (PyErr_Occurred()) {
    goto done;
  }
  if (!householder_fit(x, n, p, a, y, m, c)) {
    result = Py_NewRef(Py_NotImplemented);
    goto done;
  }
  PyObject *coefficients = float_rows(c, p, m, false);
  if (coefficients != NULL) {
    result = Py_BuildValue("(Nd)", coefficients, span);
  }
done:
  PyMem_Free(memory);
  Py_XDECREF(times);
  Py_XDECREF(rows);
  return result;
}


/* ------------------------------------------------------------------------------------------ */
/* the prediction's forecasts from the detector's latest samples (core.detector.predictor) */

/* one float of a sequence item: a float read directly, anything else converted */
static inline double item_double(PyObject *o)
{
  return PyFloat_CheckExact(o) ? PyFloat_AS_DOUBLE(o) : PyFloat_AsDouble(o);
}

/*
 * The window [first, end) of a stream as contiguous arrays: x = (time - t) / span with
 * span = max(t - times[first], 1e-9) (as polyfit), and the first m floats of each row into y
 * (n x m, row-major). Lists of tuples of floats are read directly. False with an exception.
 */
static bool gather_window(PyObject *times, PyObject *rows, Py_ssize_t first, Py_ssize_t end,
                          int m, double t, double *x, double *y, double *span)
{
  if (!PyList_Check(times) || !PyList_Check(rows)) {
    PyErr_SetString(PyExc_TypeError, "a forecast's times and rows must be lists");
    return false;
  }
  if (first < 0 || end <= first || end > PyList_GET_SIZE(times) ||
      end > PyList_GET_SIZE(rows)) {
    PyErr_SetString(PyExc_IndexError, "a forecast's window is outside its samples");
    return false;
  }
  double t_first = item_double(PyList_GET_ITEM(times, first));
  if (t_first == -1.0 && PyErr_Occurred()) {
    return false;
  }
  *span = max_of(t - t_first, 1e-9);
  for (Py_ssize_t i = first; i < end; i++) {
    double time = item_double(PyList_GET_ITEM(times, i));
    if (time == -1.0 && PyErr_Occurred()) {
      return false;
    }
    x[i - first] = (time - t) / *span;
    PyObject *row = PyList_GET_ITEM(rows, i);
    double *out = y + (i - first) * m;
    if (PyTuple_CheckExact(row) && PyTuple_GET_SIZE(row) >= m) {
      for (int k = 0; k < m; k++) {
        out[k] = item_double(PyTuple_GET_ITEM(row, k));
      }
      if (PyErr_Occurred()) {
        return false;
      }
    } else if (row == Py_None || !read_floats(row, out, m, "a sample of the forecast's window")) {
      if (!PyErr_Occurred()) {
        PyErr_SetString(PyExc_TypeError, "a sample of the forecast's window is missing");
      }
      return false;
    }
  }
  return true;
}

/*
 * The least-squares polynomial of degree min(degree, n - 1) through the window (x, y), and its
 * value, first and second time derivatives at x = 0 (kinematics.derivatives' arithmetic, so
 * the same bits as polyfit followed by it): d[0..m), d[m..2m), d[2m..3m). False when rank
 * deficient (the caller asks LAPACK); -1 with an exception (no memory).
 */
static int fit_at_zero(const double *x, Py_ssize_t n, int degree, double *y, int m, double span,
                       double *d)
{
  int p = (int)((degree < n - 1 ? degree : n - 1) + 1);
  double *a = PyMem_Malloc(sizeof(double) * (size_t)(n * p + p * m));
  if (a == NULL) {
    PyErr_NoMemory();
    return -1;
  }
  double *c = a + n * p;
  bool solved = householder_fit(x, n, p, a, y, m, c);
  if (solved) {
    double squared = pow(span, 2.0); /* Python's span ** 2 */
    for (int k = 0; k < m; k++) {
      d[k] = c[k];
      d[m + k] = p > 1 ? c[m + k] / span : 0.0 * c[k];
      d[2 * m + k] = p > 2 ? 2.0 * c[2 * m + k] / squared : 0.0 * c[k];
    }
  }
  PyMem_Free(a);
  return solved;
}

static PyObject *float_tuple(const double *x, int count) { return float_sequence(x, count, true); }

/*
 * The ball under gravity and quadratic drag from its state at t0 (BallForecast.ballistic):
 * acceleration = gravity - drag |v| v; out = t0, position, velocity, acceleration.
 */
static void ballistic(double t0, const double *position, const double *velocity,
                      const double *gravity, double drag, double *out)
{
  double speed = sqrt(velocity[0] * velocity[0] + velocity[1] * velocity[1] +
                      velocity[2] * velocity[2]);
  double s = drag * speed;
  out[0] = t0;
  for (int k = 0; k < 3; k++) {
    out[1 + k] = position[k];
    out[4 + k] = velocity[k];
    out[7 + k] = gravity[k] - velocity[k] * s;
  }
}

/*
 * The fraction along knob-tip of the axis point with the smallest acceleration, from the
 * knob's and the tip's (m/s^2; every axis point's is linear in the fraction between them),
 * within [-0.5, 1]; 0 when both are equal (kinematics.least_accelerating)
 */
static double least_accelerating(Vec knob, Vec tip)
{
  Vec change = v_sub(tip, knob);
  double size = v_dot(change, change);
  return size == 0.0 ? 0.0 : min_of(1.0, max_of(-0.5, -v_dot(knob, change) / size));
}

/*
 * The extrapolated bat from the rates at t0 of its knob + tip + cumulative turn fit (first and
 * second time derivatives of the 10 components) and its knob and tip at t0: the pivot is the
 * axis point that accelerates least (kinematics.least_accelerating) moving with the fit's
 * velocity and acceleration there, turning about the angular velocity's axis at its rate and
 * the angular acceleration along it (prediction.turn_axis_and_rates). out: BatForecast's 21
 * numbers.
 */
static void bat_from_rates(double t0, const double *first, const double *second, Vec knob,
                           Vec tip, double *out)
{
  Vec knob_accel = {second[0], second[1], second[2]}, tip_accel = {second[3], second[4], second[5]};
  double fraction = least_accelerating(knob_accel, tip_accel);
  Vec velocity = v_lerp((Vec){first[0], first[1], first[2]}, (Vec){first[3], first[4], first[5]},
                        fraction);
  Vec acceleration = v_lerp(knob_accel, tip_accel, fraction);
  Vec rate = {first[6], first[7], first[8]}, rate_change = {second[6], second[7], second[8]};
  double turn = sqrt(rate.x * rate.x + rate.y * rate.y + rate.z * rate.z);
  Vec axis = {0.0, 0.0, 1.0};
  double turn_change = 0.0;
  if (turn != 0.0) {
    axis = v_scale(rate, 1.0 / turn);
    turn_change = v_dot(rate_change, axis);
  }
  Vec pivot = v_lerp(knob, tip, fraction);
  Vec parts[6] = {pivot, velocity, acceleration, v_sub(knob, pivot), v_sub(tip, pivot), axis};
  out[0] = t0;
  for (int i = 0; i < 6; i++) {
    out[1 + 3 * i] = parts[i].x;
    out[2 + 3 * i] = parts[i].y;
    out[3 + 3 * i] = parts[i].z;
  }
  out[19] = turn;
  out[20] = turn_change;
}

#define BALL_COMPONENTS 3
#define BAT_COMPONENTS 10 /* knob, tip, cumulative turn (swing x, y, z, roll) */

/* a ball sample this far (m) off the parabola of the others in its window, and BALL_GLITCH_RATIO
 * times what their own scatter leaves it off by (the distance's 1 sigma per coordinate), is a
 * tracker's glitch a forecast leaves out */
#define BALL_GLITCH_FLOOR 0.01
#define BALL_GLITCH_RATIO 5.0
#define BALL_GLITCH_MIN_SAMPLES 6

/* how far (m) a point is from the parabola d (value, rate, acceleration at 0) at time t (s) */
static double parabola_miss(const double *d, double t, const double *point)
{
  double sum = 0.0;
  for (int k = 0; k < 3; k++) {
    double e = d[k] + d[3 + k] * t + 0.5 * d[6 + k] * t * t - point[k];
    sum += e * e;
  }
  return sqrt(sum);
}

/*
 * v' (V'V)^-1 v for v = (1, u, u^2) and V'V the moments sums[k] = sum x^k (k = 0..4) of a
 * parabola's samples: a sample's leverage on their fit at u, or the variance (over sigma^2) of
 * that fit's value at another u; infinite where V'V is singular
 */
static double parabola_leverage(const double *sums, double u)
{
  double a = sums[0], b = sums[1], c = sums[2], e = sums[3], f = sums[4], w = u * u;
  double c11 = c * f - e * e, c12 = c * e - b * f, c13 = b * e - c * c;
  double c22 = a * f - c * c, c23 = b * c - a * e, c33 = a * c - b * b;
  double determinant = a * c11 + b * c12 + c * c13;
  if (!(determinant > 0.0)) {
    return INFINITY;
  }
  return (c11 + 2.0 * c12 * u + (2.0 * c13 + c22) * w + 2.0 * c23 * u * w + c33 * w * w) /
         determinant;
}

/*
 * How far samples a and b of a ball window (x, y: n samples of 3 coordinates; b = a for one) are
 * off the parabola of the others, in units of what the others' scatter leaves a sample off by
 * there (their residuals' sigma per coordinate times sqrt(1 + that parabola's variance at it)):
 * the smaller of the two ratios, 0 where either is BALL_GLITCH_FLOOR off or less or the fit is
 * rank deficient, -1 with an exception (no memory). sums: the window's moments (sum x^k, k =
 * 0..4); wx, wy: room for n samples.
 */
static double glitch_ratio(const double *x, Py_ssize_t n, const double *y, double span,
                           const double *sums, Py_ssize_t a, Py_ssize_t b, double *wx, double *wy)
{
  double others[5], d[9];
  Py_ssize_t m = 0;
  for (int k = 0; k < 5; k++) {
    others[k] = sums[k] - pow(x[a], (double)k) - (b != a ? pow(x[b], (double)k) : 0.0);
  }
  for (Py_ssize_t i = 0; i < n; i++) {
    if (i != a && i != b) {
      wx[m] = x[i];
      memcpy(wy + 3 * m, y + 3 * i, 3 * sizeof(double));
      m++;
    }
  }
  int solved = fit_at_zero(wx, m, 2, wy, BALL_COMPONENTS, span, d);
  if (solved <= 0) {
    return solved < 0 ? -1.0 : 0.0;
  }
  double scatter = 0.0, ratio = INFINITY;
  for (Py_ssize_t i = 0; i < n; i++) {
    if (i != a && i != b) {
      double miss = parabola_miss(d, x[i] * span, y + 3 * i);
      scatter += miss * miss;
    }
  }
  double sigma = sqrt(scatter / (3.0 * (double)(m - 3)));
  for (int j = 0; j < 2; j++) {
    Py_ssize_t i = j ? b : a;
    double off = parabola_miss(d, x[i] * span, y + 3 * i);
    double spread = sigma * sqrt(1.0 + parabola_leverage(others, x[i]));
    if (!(off > BALL_GLITCH_FLOOR)) {
      return 0.0;
    }
    ratio = fmin(ratio, spread > 0.0 ? off / spread : INFINITY);
  }
  return ratio;
}

/*
 * Leave up to two glitches out of a ball window (x, y: gather_window's, n samples of 3
 * coordinates). The candidates: the three samples whose miss from the window's parabola over 1
 * - its leverage (the miss from the parabola of the others, to first order) is the largest (a
 * window's end pulls the parabola its way, and a glitch the samples beside it). Of the first two,
 * the one farther off the parabola of the others beyond their scatter (glitch_ratio), where that
 * is BALL_GLITCH_RATIO or more (a tracker's mislabelled blob, a reflection: 10 cm bends a
 * forecast's parabola by centimetres), is left out, and the rest judged so once more; unless
 * a pair of the three, both off the parabola of the rest, is clearer off (the smaller of their
 * two ratios; two glitches hide each other from the test of one, and pull the sample beside
 * them off), in a window of 8 samples or more: then that pair. Windows of fewer than
 * BALL_GLITCH_MIN_SAMPLES are kept whole. Returns how many samples are kept (x and y
 * compacted), -1 with an exception (no memory); where it kept them all and fitted their
 * parabola, that fit (fit_at_zero's value, rate and acceleration at 0) is in whole[9] and
 * *fitted is true (the same bits as fitting them again).
 */
static Py_ssize_t without_ball_glitch(double *x, Py_ssize_t n, double *y, double span,
                                      double *whole, bool *fitted)
{
  *fitted = false;
  if (n < BALL_GLITCH_MIN_SAMPLES) {
    return n;
  }
  double *work = PyMem_Malloc(sizeof(double) * (size_t)(4 * n));
  if (work == NULL) {
    PyErr_NoMemory();
    return -1;
  }
  double *wx = work, *wy = work + n;
  Py_ssize_t kept = n;
  bool first_fit = false;
  for (int pass = 0; pass < 2 && kept >= BALL_GLITCH_MIN_SAMPLES; pass++) {
    double d[9], sums[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
    memcpy(wy, y, sizeof(double) * (size_t)(3 * kept));
    int solved = fit_at_zero(x, kept, 2, wy, BALL_COMPONENTS, span, d);
    if (solved < 0) {
      kept = -1;
      break;
    }
    if (solved == 0) {
      break;
    }
    if (pass == 0) {
      memcpy(whole, d, sizeof d);
      first_fit = true;
    }
    for (Py_ssize_t i = 0; i < kept; i++) {
      double power = 1.0;
      for (int k = 0; k < 5; k++) {
        sums[k] += power;
        power *= x[i];
      }
    }
    Py_ssize_t candidates[3] = {-1, -1, -1};
    double far[3] = {0.0, 0.0, 0.0};
    for (Py_ssize_t i = 0; i < kept; i++) {
      double miss = parabola_miss(d, x[i] * span, y + 3 * i);
      if (!(miss > 0.5 * BALL_GLITCH_FLOOR)) {
        continue; /* (a window without a glitch: no leverage made) */
      }
      double h = parabola_leverage(sums, x[i]);
      double deleted = h < 1.0 ? miss / (1.0 - h) : INFINITY;
      int slot = 3;
      while (slot > 0 && deleted > far[slot - 1]) {
        slot--;
      }
      if (slot < 3) {
        for (int j = 2; j > slot; j--) {
          far[j] = far[j - 1], candidates[j] = candidates[j - 1];
        }
        far[slot] = deleted, candidates[slot] = i;
      }
    }
    Py_ssize_t out[2] = {-1, -1};
    double clearest = BALL_GLITCH_RATIO;
    for (int j = 0; j < 2 && candidates[j] >= 0; j++) {
      double ratio = glitch_ratio(x, kept, y, span, sums, candidates[j], candidates[j], wx, wy);
      if (ratio < 0.0) {
        kept = -1;
        break;
      }
      if (ratio >= clearest) {
        clearest = ratio, out[0] = candidates[j];
      }
    }
    /* a pair of the three the rest leave clearer off than one alone (a glitch beside it) */
    for (int j = 0; pass == 0 && kept >= 8 && j < 3; j++) {
      Py_ssize_t a = candidates[j], b = candidates[(j + 1) % 3];
      double ratio = a >= 0 && b >= 0 ? glitch_ratio(x, kept, y, span, sums, a, b, wx, wy) : 0.0;
      if (ratio < 0.0) {
        kept = -1;
        break;
      }
      if (ratio >= clearest) {
        clearest = ratio, out[0] = a > b ? a : b, out[1] = a > b ? b : a;
      }
    }
    if (kept < 0 || out[0] < 0) {
      break;
    }
    for (int j = 0; j < 2 && out[j] >= 0; j++) { /* the later one first */
      Py_ssize_t i = out[j];
      memmove(x + i, x + i + 1, sizeof(double) * (size_t)(kept - i - 1));
      memmove(y + 3 * i, y + 3 * (i + 1), sizeof(double) * (size_t)(3 * (kept - i - 1)));
      kept--;
    }
    if (out[1] >= 0) {
      break;
    }
  }
  *fitted = first_fit && kept == n;
  PyMem_Free(work);
  return kept;
}

/*
 * The ball's forecast (its 10 numbers in out) from the polynomial of `degree` through its
 * window (x, y: gather_window's, the fit's origin t0), a glitch left out (without_ball_glitch):
 * 1, or 0 when rank deficient, -1 with an exception (no memory). x and y are overwritten.
 */
static int ball_fit_forecast(double *x, Py_ssize_t n, int degree, double *y, double span,
                             double t0, const double *gravity, double drag, double *out)
{
  double d[3 * BALL_COMPONENTS];
  bool fitted;
  n = without_ball_glitch(x, n, y, span, d, &fitted);
  if (n < 0) {
    return -1;
  }
  int solved = fitted && degree == 2 ? 1 : fit_at_zero(x, n, degree, y, BALL_COMPONENTS, span, d);
  if (solved > 0) {
    ballistic(t0, d, d + BALL_COMPONENTS, gravity, drag, out);
  }
  return solved;
}

/* a lift is fitted over at least this many seconds and samples of the ball's flight */
#define LIFT_MIN_SPAN 0.05
#define LIFT_MIN_SAMPLES 6

/*
 * The ball's lift (the detector's lift_window): what its flight over the window (x, y: gather_window's
 * of the ball's samples up to the forecast's, origin t0) accelerates by beyond gravity and drag,
 * the spin's Magnus force: the least-squares parabola's acceleration less gravity - drag |v| v at
 * the velocity it has at the window's middle, added to the forecast's acceleration (out[7..9]),
 * times its gain max(0, 1 - 3 var / |lift|^2): var is the variance of each of the acceleration's
 * coordinates from the scatter of the samples about the parabola (its residuals' mean square over
 * 3 (n - 3) degrees of freedom, times 4 / (R_22^2 span^4) from the QR's last diagonal), so a lift
 * the noise could have made is left out (an estimate of the Wiener gain |lift|^2 / (|lift|^2 +
 * 3 var)). A pitch's lift is 1-7 m/s^2; 1 mm of noise over 0.1 s of flight at 90 Hz scatters
 * the acceleration by about 0.85 m/s^2, over 0.25 s by 0.1 m/s^2. Nothing is added over less than
 * LIFT_MIN_SPAN s or LIFT_MIN_SAMPLES samples (a glitch left out: without_ball_glitch), or
 * where the fit is rank deficient. 0 or 1 (added), -1 with an exception (no memory). x and y are
 * overwritten.
 */
static int add_lift(double *x, Py_ssize_t n, double *y, double span, const double *gravity,
                    double drag, double *out)
{
  double whole[9];
  bool fitted;
  n = without_ball_glitch(x, n, y, span, whole, &fitted);
  if (n < 0) {
    return -1;
  }
  if (n < LIFT_MIN_SAMPLES || (x[n - 1] - x[0]) * span < LIFT_MIN_SPAN) {
    return 0;
  }
  double *a = PyMem_Malloc(sizeof(double) * (size_t)(n * 3 + 9));
  if (a == NULL) {
    PyErr_NoMemory();
    return -1;
  }
  double *c = a + n * 3;
  bool solved = householder_fit(x, n, 3, a, y, BALL_COMPONENTS, c);
  if (solved) {
    double last = a[8], scatter = 0.0; /* R_22; the residuals' sum of squares */
    for (Py_ssize_t i = 3 * 3; i < n * 3; i++) {
      scatter += y[i] * y[i];
    }
    double squared = pow(span, 2.0), middle = 0.5 * (x[0] + x[n - 1]) * span;
    double variance = scatter / (3.0 * (double)(n - 3)) * 4.0 /
                      (last * last * squared * squared);
    double v[3], lift[3], size = 0.0;
    for (int k = 0; k < 3; k++) {
      double acceleration = 2.0 * c[6 + k] / squared;
      v[k] = c[3 + k] / span + acceleration * middle;
      lift[k] = acceleration;
    }
    double s = drag * sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
    for (int k = 0; k < 3; k++) {
      lift[k] -= gravity[k] - v[k] * s;
      size += lift[k] * lift[k];
    }
    double gain = size > 0.0 ? max_of(0.0, 1.0 - 3.0 * variance / size) : 0.0;
    for (int k = 0; k < 3; k++) {
      out[7 + k] += gain * lift[k];
    }
  }
  PyMem_Free(a);
  return solved;
}

/*
 * The bat's forecast (its 21 numbers in out) from the polynomial of `degree` through its window
 * (x, y: knob + tip + cumulative turn rows, the fit's origin t, the newest sample's time),
 * extrapolated from the newest row's knob and tip: as ball_fit_forecast.
 */
static int bat_fit_forecast(const double *x, Py_ssize_t n, int degree, double *y, double span,
                            double t, double *out)
{
  /* the newest row, before the fit overwrites y: knob and tip at t */
  const double *last = y + (n - 1) * BAT_COMPONENTS;
  Vec knob = {last[0], last[1], last[2]}, tip = {last[3], last[4], last[5]};
  double d[3 * BAT_COMPONENTS];
  int solved = fit_at_zero(x, n, degree, y, BAT_COMPONENTS, span, d);
  if (solved > 0) {
    bat_from_rates(t, d + BAT_COMPONENTS, d + 2 * BAT_COMPONENTS, knob, tip, out);
  }
  return solved;
}

/*
 * Rows of knob + tip + the turn from the sample before (y, n x 10) made knob + tip + the turn
 * since the first row, in place: the first row's turn zero, each next the last plus its step,
 * summed in order.
 */
static void cumulate_turns(double *y, Py_ssize_t n)
{
  for (int c = 6; c < BAT_COMPONENTS; c++) {
    y[c] = 0.0;
  }
  for (Py_ssize_t i = 1; i < n; i++) {
    double *row = y + i * BAT_COMPONENTS;
    for (int c = 6; c < BAT_COMPONENTS; c++) {
      row[c] = row[c - BAT_COMPONENTS] + row[c];
    }
  }
}

/*
 * ball_forecast(times, points, first, end, t0, degree, gravity, drag, lift_first) -> the
 * BallForecast's 10 numbers (t0, position, velocity, acceleration: with the lift of samples
 * lift_first .. end - 1, add_lift), or NotImplemented (a rank-deficient fit)
 */
static PyObject *py_ball_forecast(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t first, end, lift_first;
  long degree;
  double t0, drag, gravity[3];
  if (nargs != 9) {
    PyErr_SetString(PyExc_TypeError, "ball_forecast(times, points, first, end, t0, degree, "
                                     "gravity, drag, lift_first)");
    return NULL;
  }
  if (((first = PyLong_AsSsize_t(args[2])) == -1 && PyErr_Occurred()) ||
      ((end = PyLong_AsSsize_t(args[3])) == -1 && PyErr_Occurred()) ||
      ((lift_first = PyLong_AsSsize_t(args[8])) == -1 && PyErr_Occurred()) ||
      ((degree = PyLong_AsLong(args[5])) == -1 && PyErr_Occurred()) ||
      !read_floats(args[6], gravity, 3, "gravity")) {
    return NULL;
  }
  if (!read_number(args[4], &t0) || !read_number(args[7], &drag) || degree < 0 ||
      degree > MAX_FIT_DEGREE) {
    PyErr_SetString(PyExc_ValueError, "ball_forecast: numbers t0 and drag, 0 <= degree <= 15");
    return NULL;
  }
  if (lift_first < 0 || lift_first > end) {
    PyErr_SetString(PyExc_IndexError, "ball_forecast: lift_first must be in [0, end]");
    return NULL;
  }
  Py_ssize_t n = end - first, lift = end - lift_first, wide = n > lift ? n : lift;
  double *memory = wide > 0 ? PyMem_Malloc(sizeof(double) * (size_t)(wide * (1 + BALL_COMPONENTS)))
                            : NULL;
  if (wide > 0 && memory == NULL) {
    return PyErr_NoMemory();
  }
  double *x = memory, *y = memory + wide, span, out[10];
  PyObject *result = NULL;
  if (gather_window(args[0], args[1], first, end, BALL_COMPONENTS, t0, x, y, &span)) {
    int solved = ball_fit_forecast(x, n, (int)degree, y, span, t0, gravity, drag, out);
    if (solved > 0 &&
        (lift < LIFT_MIN_SAMPLES ||
         (gather_window(args[0], args[1], lift_first, end, BALL_COMPONENTS, t0, x, y, &span) &&
          add_lift(x, lift, y, span, gravity, drag, out) >= 0))) {
      result = float_tuple(out, 10);
    } else if (solved == 0) {
      result = Py_NewRef(Py_NotImplemented);
    }
  }
  PyMem_Free(memory);
  return result;
}

/* ballistic(t0, position, velocity, gravity, drag) -> the BallForecast's 10 numbers */
static PyObject *py_ballistic(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  double t0, drag, position[3], velocity[3], gravity[3], out[10];
  if (nargs != 5) {
    PyErr_SetString(PyExc_TypeError, "ballistic(t0, position, velocity, gravity, drag)");
    return NULL;
  }
  if (!read_floats(args[1], position, 3, "position") ||
      !read_floats(args[2], velocity, 3, "velocity") ||
      !read_floats(args[3], gravity, 3, "gravity")) {
    return NULL;
  }
  if (!read_number(args[0], &t0) || !read_number(args[4], &drag)) {
    PyErr_SetString(PyExc_TypeError, "ballistic(): numbers t0 and drag expected");
    return NULL;
  }
  ballistic(t0, position, velocity, gravity, drag, out);
  return float_tuple(out, 10);
}

/*
 * The bat's forecast (21 numbers, a tuple) from its window [first, end) of a stream's lists
 * (times; rows of knob + tip + cumulative turn, or with `steps` of knob + tip + the turn from
 * the sample before: cumulate_turns), fitted at t (the newest sample's time); NotImplemented
 * when rank deficient; NULL with an exception.
 */
static PyObject *bat_window_result(PyObject *times, PyObject *rows, Py_ssize_t first,
                                   Py_ssize_t end, int degree, double t, bool steps)
{
  Py_ssize_t n = end - first;
  double *memory = PyMem_Malloc(sizeof(double) * (size_t)(n * (1 + BAT_COMPONENTS)));
  if (memory == NULL) {
    return PyErr_NoMemory();
  }
  double *x = memory, *y = memory + n, span, out[21];
  PyObject *result = NULL;
  if (gather_window(times, rows, first, end, BAT_COMPONENTS, t, x, y, &span)) {
    if (steps) {
      cumulate_turns(y, n);
    }
    int solved = bat_fit_forecast(x, n, degree, y, span, t, out);
    if (solved > 0) {
      result = float_tuple(out, 21);
    } else if (solved == 0) {
      result = Py_NewRef(Py_NotImplemented);
    }
  }
  PyMem_Free(memory);
  return result;
}

/*
 * bat_forecast(times, rows, first, end, degree) -> the BatForecast's 21 numbers from the bat's
 * samples [first, end) (rows: knob + tip + cumulative turn, 10 floats each; at least 3
 * samples), fitted at and extrapolated from the newest, or NotImplemented (rank deficient)
 */
static PyObject *py_bat_forecast(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t first, end;
  long degree;
  if (nargs != 5) {
    PyErr_SetString(PyExc_TypeError, "bat_forecast(times, rows, first, end, degree)");
    return NULL;
  }
  if (((first = PyLong_AsSsize_t(args[2])) == -1 && PyErr_Occurred()) ||
      ((end = PyLong_AsSsize_t(args[3])) == -1 && PyErr_Occurred()) ||
      ((degree = PyLong_AsLong(args[4])) == -1 && PyErr_Occurred())) {
    return NULL;
  }
  if (degree < 0 || degree > MAX_FIT_DEGREE || end - first < 3) {
    PyErr_SetString(PyExc_ValueError, "bat_forecast: 0 <= degree <= 15, at least 3 samples");
    return NULL;
  }
  if (!PyList_Check(args[0]) || end > PyList_GET_SIZE(args[0]) || first < 0) {
    PyErr_SetString(PyExc_IndexError, "a forecast's window is outside its samples");
    return NULL;
  }
  double t = item_double(PyList_GET_ITEM(args[0], end - 1)); /* the newest sample's time */
  if (t == -1.0 && PyErr_Occurred()) {
    return NULL;
  }
  return bat_window_result(args[0], args[1], first, end, (int)degree, t, false);
}

/* least_accelerating(knob, tip) -> the fraction of the least-accelerating axis point */
static PyObject *py_least_accelerating(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  double ends[6];
  if (nargs != 2) {
    PyErr_SetString(PyExc_TypeError, "least_accelerating(knob, tip)");
    return NULL;
  }
  if (!read_floats(args[0], ends, 3, "knob") || !read_floats(args[1], ends + 3, 3, "tip")) {
    return NULL;
  }
  return PyFloat_FromDouble(least_accelerating((Vec){ends[0], ends[1], ends[2]},
                                               (Vec){ends[3], ends[4], ends[5]}));
}

/* bat_from_rates(t0, first, second, knob, tip) -> the BatForecast's 21 numbers (10 rates each) */
static PyObject *py_bat_from_rates(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  double t0, first[BAT_COMPONENTS], second[BAT_COMPONENTS], ends[6], out[21];
  if (nargs != 5) {
    PyErr_SetString(PyExc_TypeError, "bat_from_rates(t0, first, second, knob, tip)");
    return NULL;
  }
  if (!read_floats(args[1], first, BAT_COMPONENTS, "first derivatives") ||
      !read_floats(args[2], second, BAT_COMPONENTS, "second derivatives") ||
      !read_floats(args[3], ends, 3, "knob") || !read_floats(args[4], ends + 3, 3, "tip")) {
    return NULL;
  }
  if (!read_number(args[0], &t0)) {
    PyErr_SetString(PyExc_TypeError, "bat_from_rates(): a number t0 expected");
    return NULL;
  }
  bat_from_rates(t0, first, second, (Vec){ends[0], ends[1], ends[2]},
                 (Vec){ends[3], ends[4], ends[5]}, out);
  return float_tuple(out, 21);
}

/* ------------------------------------------------------------------------------------------ */
/* the c2 model's window fits (core.motion.splines, core.motion.c2) and the noise estimate's
 * residuals (core.detector.noise): plain doubles, each operation in the order the Python they
 * replaced took, so the same bits */

static PyObject *math_dist = NULL; /* math.dist, a bat's length (its own exact summation) */
static PyObject *knob_name = NULL, *tip_name = NULL; /* "knob", "tip" */
static PyObject *quaternion_name = NULL;              /* "quaternion" */
static PyObject *position_name = NULL;                /* "position" */
/* the path pieces' attributes c2_deviation reads (motion.points: PointPath, AngleCubic) */
enum {
  PIECE_T0, PIECE_T1, PIECE_H, PIECE_A, PIECE_END, PIECE_B, PIECE_C, PIECE_D, PIECE_ACCEL0,
  PIECE_ACCEL_RATE, PIECE_CURVED, PIECE_E, PIECE_F, PIECE_NAMES
};
static const char *const piece_attributes[PIECE_NAMES] = {
    "t0", "t1", "h", "a", "end", "b", "c", "d", "accel0", "accel_rate", "curved", "e", "f"};
static PyObject *piece_names[PIECE_NAMES];
static volatile double squared_power = 2.0; /* pow(x, 2): Python's x ** 2 (libm's pow, which
                                               may differ from x * x in the last bit; volatile:
                                               not folded into x * x) */

/*
 * The slopes at knots start..n-1 of the not-a-knot cubic spline through n >= 4 knots: stamps
 * t (s, increasing), values y (n x m, row-major); out: (n - start) x m, row-major. The
 * tridiagonal system (its matrix from the steps only) eliminated by Thomas' forward sweep
 * without pivoting (the first elimination leaves h0 + h1 on the diagonal, the inner rows are
 * diagonally dominant), then each column solved: knot by knot, every column at each knot (the
 * columns' divisions independent of one another, not one column's chain after another's;
 * each column's operations those of a column alone), each right-hand side kept in out until
 * the back substitution replaces it. work: at least 4 n + 2 m doubles.
 */
static void not_a_knot_solve(const double *t, Py_ssize_t n, const double *y, Py_ssize_t m,
                             Py_ssize_t start, double *out, double *work)
{
  double *h = work, *diagonal = h + n, *above = diagonal + n, *factors = above + n;
  double *r = factors + n, *chord = r + m; /* per column: the sweep's last value, chord i - 1 */
  for (Py_ssize_t i = 0; i < n - 1; i++) {
    h[i] = t[i + 1] - t[i];
  }
  double h0 = h[0], h1 = h[1], hm = h[n - 3], hl = h[n - 2];
  /* inner row i: below h[i], diagonal 2 (h[i - 1] + h[i]), above h[i - 1] */
  diagonal[0] = h1;
  above[0] = h0 + h1;
  for (Py_ssize_t i = 1; i < n - 1; i++) {
    diagonal[i] = 2.0 * (h[i - 1] + h[i]);
    above[i] = h[i - 1];
  }
  diagonal[n - 1] = hm;
  factors[0] = 0.0;
  for (Py_ssize_t i = 1; i < n; i++) {
    double factor = (i < n - 1 ? h[i] : hl + hm) / diagonal[i - 1];
    diagonal[i] -= factor * above[i - 1];
    factors[i] = factor;
  }
  double first = (h0 + 2.0 * (h0 + h1)) * h1, h0_squared = pow(h0, squared_power);
  double span0 = h0 + h1, hl_squared = pow(hl, squared_power);
  double last = (2.0 * (hm + hl) + hl) * hm, span1 = hm + hl;
#define CHORD(i, c) ((y[((i) + 1) * m + (c)] - y[(i) * m + (c)]) / h[i])
  for (Py_ssize_t c = 0; c < m; c++) {
    double d0 = CHORD(0, c);
    r[c] = (first * d0 + h0_squared * CHORD(1, c)) / span0;
    chord[c] = d0;
    if (start == 0) {
      out[c] = r[c];
    }
  }
  /* forward: each inner row's right-hand side, less its factor times the row above's */
  for (Py_ssize_t i = 1; i < n - 1; i++) {
    double *row = i >= start ? out + (i - start) * m : NULL;
    for (Py_ssize_t c = 0; c < m; c++) {
      double d = CHORD(i, c);
      r[c] = 3.0 * (h[i] * chord[c] + h[i - 1] * d) - factors[i] * r[c];
      chord[c] = d;
      if (row != NULL) {
        row[c] = r[c];
      }
    }
  }
  double *row = out + (n - 1 - start) * m; /* back from the last knot */
  for (Py_ssize_t c = 0; c < m; c++) {
    r[c] = ((hl_squared * CHORD(n - 3, c) + last * CHORD(n - 2, c)) / span1 -
            factors[n - 1] * r[c]) / diagonal[n - 1];
    row[c] = r[c];
  }
#undef CHORD
  for (Py_ssize_t i = n - 2; i >= start; i--) {
    row = out + (i - start) * m;
    for (Py_ssize_t c = 0; c < m; c++) {
      r[c] = (row[c] - above[i] * r[c]) / diagonal[i];
      row[c] = r[c];
    }
  }
}

#define QUINTIC 5 /* the degree of quintic_solve's spline */

/*
 * The derivatives (per s) of the degree-`degree` B-splines nonzero on [T[left], T[left + 1]]
 * (B_{left-degree} .. B_left) from the same of degree - 1 (`lower`, `degree` of them):
 * B'_{i,d} = d (B_{i,d-1} / (T[i+d] - T[i]) - B_{i+1,d-1} / (T[i+d+1] - T[i+1])) (de Boor, A
 * Practical Guide to Splines, ch. X). Every span divided by holds [T[left], T[left + 1]].
 */
static void spline_derivatives(const double *T, Py_ssize_t left, int degree, const double *lower,
                               double *out)
{
  for (int r = 0; r <= degree; r++) {
    Py_ssize_t i = left - degree + r;
    double sum = 0.0;
    if (r > 0) {
      sum += lower[r - 1] / (T[i + degree] - T[i]);
    }
    if (r < degree) {
      sum -= lower[r] / (T[i + degree + 1] - T[i + 1]);
    }
    out[r] = degree * sum;
  }
}

/*
 * The 6 B-splines of degree 5 on knots T nonzero at x in [T[left], T[left + 1]] (B_{left-5} ..
 * B_left): their values, first and second derivatives (per s and s^2), by de Boor's recurrence
 * (BSPLVB) keeping the values of degree 3 and 4 for the derivatives.
 */
static void quintic_basis(const double *T, Py_ssize_t left, double x, double *values,
                          double *first, double *second)
{
  double before[QUINTIC + 1], after[QUINTIC + 1], cubic[4], quartic[5], quartic_rate[5];
  values[0] = 1.0;
  for (int j = 1; j <= QUINTIC; j++) {
    before[j] = x - T[left + 1 - j];
    after[j] = T[left + j] - x;
    double saved = 0.0;
    for (int r = 0; r < j; r++) {
      double term = values[r] / (after[r + 1] + before[j - r]);
      values[r] = saved + after[r + 1] * term;
      saved = before[j - r] * term;
    }
    values[j] = saved;
    if (j == 3) {
      memcpy(cubic, values, sizeof cubic);
    } else if (j == 4) {
      memcpy(quartic, values, sizeof quartic);
    }
  }
  spline_derivatives(T, left, QUINTIC, quartic, first);
  spline_derivatives(T, left, 4, cubic, quartic_rate);
  spline_derivatives(T, left, QUINTIC, quartic_rate, second);
}

/* the knot interval [T[left], T[left + 1]] quintic_solve evaluates stamp i (of n) in */
static inline Py_ssize_t quintic_left(Py_ssize_t i, Py_ssize_t n)
{
  return i + 3 < QUINTIC ? QUINTIC : i + 3 > n - 1 ? n - 1 : i + 3;
}

/*
 * The slopes and second derivatives at knots start..n-1 of the not-a-knot quintic spline
 * through n >= 6 knots: the degree-5 spline interpolating (t, y) whose knots are the stamps but
 * t[1], t[2], t[n-3] and t[n-2] (de Boor's not-a-knot choice for an odd degree: the pieces on
 * either side of each left-out stamp are one quintic, so the end pieces are as accurate as the
 * inner ones; six knots give the one quintic through them). Stamps t (s, increasing), values y
 * (n x m, row-major); slopes and seconds: (n - start) x m each, row-major. B-spline
 * collocation: the basis at each stamp (quintic_basis), the n x n system (its matrix from the
 * stamps alone) eliminated without pivoting, which is stable for it (a collocation matrix at
 * sites in its B-splines' supports is totally positive: de Boor, ch. XIII), every column at
 * each step in a fixed order (the same bits on every machine), then each knot's derivatives
 * from its six B-splines'. work: at least n (n + 13 + m) + 6 doubles.
 */
static void quintic_solve(const double *t, Py_ssize_t n, const double *y, Py_ssize_t m,
                          Py_ssize_t start, double *slopes, double *seconds, double *work)
{
  double *T = work, *a = T + n + 6, *d1 = a + n * n, *d2 = d1 + 6 * n, *c = d2 + 6 * n;
  for (int r = 0; r <= QUINTIC; r++) {
    T[r] = t[0];
    T[n + r] = t[n - 1];
  }
  for (Py_ssize_t i = 3; i <= n - 4; i++) {
    T[i + 3] = t[i];
  }
  memset(a, 0, sizeof(double) * (size_t)(n * n));
  for (Py_ssize_t i = 0; i < n; i++) { /* row i: the six B-splines at stamp i */
    Py_ssize_t left = quintic_left(i, n);
    quintic_basis(T, left, t[i], a + i * n + left - QUINTIC, d1 + 6 * i, d2 + 6 * i);
  }
  memcpy(c, y, sizeof(double) * (size_t)(n * m));
  for (Py_ssize_t p = 0; p < n - 1; p++) { /* forward elimination, no pivoting */
    double pivot = a[p * n + p];
    for (Py_ssize_t i = p + 1; i < n && i <= p + QUINTIC; i++) {
      double below = a[i * n + p];
      if (below == 0.0) {
        continue;
      }
      double factor = below / pivot;
      for (Py_ssize_t j = p; j < n; j++) {
        a[i * n + j] -= factor * a[p * n + j];
      }
      for (Py_ssize_t k = 0; k < m; k++) {
        c[i * m + k] -= factor * c[p * m + k];
      }
    }
  }
  for (Py_ssize_t p = n - 1; p >= 0; p--) { /* back substitution: the coefficients */
    for (Py_ssize_t k = 0; k < m; k++) {
      double sum = c[p * m + k];
      for (Py_ssize_t j = p + 1; j < n; j++) {
        sum -= a[p * n + j] * c[j * m + k];
      }
      c[p * m + k] = sum / a[p * n + p];
    }
  }
  for (Py_ssize_t i = start; i < n; i++) {
    const double *coefficients = c + (quintic_left(i, n) - QUINTIC) * m;
    for (Py_ssize_t k = 0; k < m; k++) {
      double rate = 0.0, bend = 0.0;
      for (int r = 0; r <= QUINTIC; r++) {
        rate += d1[6 * i + r] * coefficients[r * m + k];
        bend += d2[6 * i + r] * coefficients[r * m + k];
      }
      slopes[(i - start) * m + k] = rate;
      seconds[(i - start) * m + k] = bend;
    }
  }
}

/* an integer (anything with __index__); false with an exception */
static bool read_index(PyObject *o, Py_ssize_t *i)
{
  *i = PyNumber_AsSsize_t(o, PyExc_OverflowError);
  return !(*i == -1 && PyErr_Occurred());
}

/* n rows of m floats (each a sequence) into y (n x m, row-major); false with an exception */
static bool read_rows(PyObject *rows, Py_ssize_t n, Py_ssize_t m, double *y, const char *what)
{
  for (Py_ssize_t i = 0; i < n; i++) {
    PyObject *row = PySequence_Fast_GET_ITEM(rows, i);
    double *out = y + i * m;
    if (PyTuple_CheckExact(row) && PyTuple_GET_SIZE(row) == m) {
      for (Py_ssize_t k = 0; k < m; k++) {
        out[k] = item_double(PyTuple_GET_ITEM(row, k));
      }
      if (PyErr_Occurred()) {
        return false;
      }
    } else if (!read_floats_or(row, out, m, what, PyExc_ValueError)) {
      return false;
    }
  }
  return true;
}

/*
 * not_a_knot(times, rows, start) -> the slopes (value units per s) of knots start..n-1 of the
 * not-a-knot cubic spline through n >= 4 rows of m values each (each column on its own), one
 * tuple per knot. not_a_knot_quintic(times, rows, start) -> (slopes, second derivatives (per
 * s^2)) of the same knots of the not-a-knot quintic spline (quintic_solve) through n >= 6 rows,
 * each a tuple per knot. rows: a sequence of rows, or an (n x m) C-contiguous float64 array
 * (read as it lies). ValueError: too few knots, rows of unequal lengths, start outside [0, n).
 */
static PyObject *spline_derivative_rows(PyObject *const *args, Py_ssize_t nargs, bool quintic)
{
  const char *name = quintic ? "not_a_knot_quintic" : "not_a_knot";
  Py_ssize_t start;
  if (nargs != 3 ||
      !read_index(args[2], &start)) {
    if (!PyErr_Occurred()) {
      PyErr_Format(PyExc_TypeError, "%s(times, rows, start)", name);
    }
    return NULL;
  }
  PyObject *times = PySequence_Fast(args[0], "times must be a sequence");
  PyObject *rows = NULL, *result = NULL;
  double *memory = NULL;
  /* rows as a 2-D C-contiguous float64 array (numpy's), read as it lies: the same numbers as
     its rows' floats */
  Py_buffer array;
  bool have_array = false;
  if (times != NULL && PyObject_CheckBuffer(args[1])) {
    if (PyObject_GetBuffer(args[1], &array, PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) == 0) {
      have_array = array.ndim == 2 && array.itemsize == sizeof(double) &&
                   array.format != NULL && strcmp(array.format, "d") == 0;
      if (!have_array) {
        PyBuffer_Release(&array);
      }
    } else {
      PyErr_Clear();
    }
  }
  if (times == NULL ||
      (!have_array && (rows = PySequence_Fast(args[1], "rows must be a sequence")) == NULL)) {
    goto done;
  }
  Py_ssize_t n = PySequence_Fast_GET_SIZE(times);
  Py_ssize_t count = have_array ? array.shape[0] : PySequence_Fast_GET_SIZE(rows);
  Py_ssize_t fewest = quintic ? QUINTIC + 1 : 4;
  if (n < fewest || count != n || start < 0 || start >= n) {
    PyErr_Format(PyExc_ValueError,
                 "%s: at least %zd knots, as many rows as times, 0 <= start < n", name, fewest);
    goto done;
  }
  Py_ssize_t m = have_array ? array.shape[1] : PyObject_Length(PySequence_Fast_GET_ITEM(rows, 0));
  if (m < 0) {
    goto done;
  }
  /* t, y, two outputs, and the larger work: 4 n + 2 m (cubic), n (n + 13 + m) + 6 (quintic) */
  size_t work_size = quintic ? (size_t)(n * (n + 13 + m) + 6) : (size_t)(4 * n + 2 * m);
  memory = PyMem_Malloc(sizeof(double) * ((size_t)(n * (1 + 3 * m)) + work_size));
  if (memory == NULL) {
    PyErr_NoMemory();
    goto done;
  }
  double *t = memory, *y = t + n, *out = y + n * m, *bends = out + n * m, *work = bends + n * m;
  for (Py_ssize_t i = 0; i < n; i++) {
    t[i] = item_double(PySequence_Fast_GET_ITEM(times, i));
  }
  if (have_array) {
    memcpy(y, array.buf, sizeof(double) * (size_t)(n * m));
  }
  if (PyErr_Occurred() ||
      (!have_array && !read_rows(rows, n, m, y, "a row of the spline's values"))) {
    goto done;
  }
  if (!quintic) {
    not_a_knot_solve(t, n, y, m, start, out, work);
    result = float_rows(out, n - start, m, true);
  } else {
    quintic_solve(t, n, y, m, start, out, bends, work);
    PyObject *rates = float_rows(out, n - start, m, true);
    PyObject *seconds = rates ? float_rows(bends, n - start, m, true) : NULL;
    result = seconds ? PyTuple_Pack(2, rates, seconds) : NULL;
    Py_XDECREF(rates);
    Py_XDECREF(seconds);
  }
done:
  PyMem_Free(memory);
  if (have_array) {
    PyBuffer_Release(&array);
  }
  Py_XDECREF(times);
  Py_XDECREF(rows);
  return result;
}

static PyObject *py_not_a_knot(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  return spline_derivative_rows(args, nargs, false);
}

static PyObject *py_not_a_knot_quintic(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  return spline_derivative_rows(args, nargs, true);
}

/*
 * flight_fit(times, rows, degree) -> (centre, scale, coefficients: degree + 1 lists of 3,
 * residual sum of squares) or NotImplemented (rank deficient): a ball's flight fit
 * (core.motion.flight.fit_flight), the least-squares polynomial of each coordinate of rows (n
 * points) in tau = (time - centre) / scale, the window's times centred and scaled onto
 * [-1, 1], by householder_fit; the residuals' sum of squares over the three coordinates is the
 * squared norm of what the reflectors leave below the first degree + 1 rows. ValueError: fewer
 * than degree + 2 points, rows and times of different lengths, times that do not increase
 * strictly, a degree outside 0..MAX_FIT_DEGREE.
 */
static PyObject *py_flight_fit(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t degree;
  if (nargs != 3 || !read_index(args[2], &degree)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "flight_fit(times, rows, degree)");
    }
    return NULL;
  }
  PyObject *times = PySequence_Fast(args[0], "times must be a sequence");
  PyObject *rows = times ? PySequence_Fast(args[1], "rows must be a sequence") : NULL;
  PyObject *result = NULL;
  double *memory = NULL;
  if (rows == NULL) {
    goto done;
  }
  Py_ssize_t n = PySequence_Fast_GET_SIZE(times);
  if (degree < 0 || degree > MAX_FIT_DEGREE) {
    PyErr_Format(PyExc_ValueError, "flight_fit: degree 0 to %d", MAX_FIT_DEGREE);
    goto done;
  }
  if (PySequence_Fast_GET_SIZE(rows) != n || n < degree + 2) {
    PyErr_Format(PyExc_ValueError, "flight_fit: a degree-%zd fit needs %zd points and as many "
                 "times, got %zd and %zd", degree, degree + 2, PySequence_Fast_GET_SIZE(rows), n);
    goto done;
  }
  int p = (int)degree + 1;
  memory = PyMem_Malloc(sizeof(double) * (size_t)(n * (2 + p + 3) + p * 3));
  if (memory == NULL) {
    PyErr_NoMemory();
    goto done;
  }
  double *t = memory, *x = t + n, *a = x + n, *y = a + n * p, *c = y + n * 3;
  for (Py_ssize_t i = 0; i < n; i++) {
    t[i] = item_double(PySequence_Fast_GET_ITEM(times, i));
    if (PyErr_Occurred() ||
        !read_floats_or(PySequence_Fast_GET_ITEM(rows, i), y + i * 3, 3,
                        "a point of the flight fit", PyExc_ValueError)) {
      goto done;
    }
    if (i > 0 && !(t[i] > t[i - 1])) {
      PyErr_SetString(PyExc_ValueError, "flight_fit: times must increase strictly");
      goto done;
    }
  }
  double centre = 0.5 * (t[0] + t[n - 1]), scale = 0.5 * (t[n - 1] - t[0]);
  for (Py_ssize_t i = 0; i < n; i++) {
    x[i] = (t[i] - centre) / scale;
  }
  if (!householder_fit(x, n, p, a, y, 3, c)) {
    result = Py_NewRef(Py_NotImplemented);
    goto done;
  }
  double residual = 0.0;
  for (Py_ssize_t i = p * 3; i < n * 3; i++) {
    residual += y[i] * y[i];
  }
  PyObject *coefficients = float_rows(c, p, 3, false);
  if (coefficients != NULL) {
    result = Py_BuildValue("(ddNd)", centre, scale, coefficients, residual);
  }
done:
  PyMem_Free(memory);
  Py_XDECREF(times);
  Py_XDECREF(rows);
  return result;
}

/*
 * flight_state(columns, centre, scale, t) -> ((x, y, z), (vx, vy, vz)): a flight fit's position
 * (m) and rate (m/s) at t (s) (core.motion.flight.FlightFit.state, the same operations in the
 * same order): the basis row in tau = (t - centre) / scale and its rate per second, power by
 * power as FlightFit._rows builds them, each coordinate's column (its coefficients from the
 * lowest power up) combined as Python's sum adds the products. TypeError: not 3 columns of one
 * count (1 to MAX_FIT_DEGREE + 1) of numbers, or not numbers.
 */
static PyObject *py_flight_state(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  double centre, scale, t;
  if (nargs != 4 || !read_number(args[1], &centre) || !read_number(args[2], &scale) ||
      !read_number(args[3], &t)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "flight_state(columns, centre, scale, t)");
    }
    return NULL;
  }
  double c[3][MAX_FIT_DEGREE + 1];
  PyObject *columns = PySequence_Fast(args[0], "flight_state: columns must be a sequence");
  if (columns == NULL) {
    return NULL;
  }
  Py_ssize_t p = PySequence_Fast_GET_SIZE(columns) == 3
                     ? PyObject_Length(PySequence_Fast_GET_ITEM(columns, 0)) : -1;
  bool ok = p >= 1 && p <= MAX_FIT_DEGREE + 1;
  for (int i = 0; ok && i < 3; i++) {
    ok = read_floats(PySequence_Fast_GET_ITEM(columns, i), c[i], p, "flight_state's column");
  }
  Py_DECREF(columns);
  if (!ok) {
    if (!PyErr_Occurred() || PyErr_ExceptionMatches(PyExc_TypeError)) {
      PyErr_Clear();
      PyErr_Format(PyExc_TypeError, "flight_state: 3 columns of 1 to %d numbers each",
                   MAX_FIT_DEGREE + 1);
    }
    return NULL;
  }
  double value[MAX_FIT_DEGREE + 1] = {1.0}, rate[MAX_FIT_DEGREE + 1] = {0.0};
  double tau = (t - centre) / scale;
  for (Py_ssize_t power = 1; power < p; power++) {
    rate[power] = (double)power * value[power - 1] / scale;
    value[power] = value[power - 1] * tau;
  }
  double position[3], velocity[3];
  for (int i = 0; i < 3; i++) {
    double at = 0.0, moving = 0.0;
    for (Py_ssize_t k = 0; k < p; k++) {
      at += value[k] * c[i][k];
      moving += rate[k] * c[i][k];
    }
    position[i] = at;
    velocity[i] = moving;
  }
  return Py_BuildValue("((ddd)(ddd))", position[0], position[1], position[2], velocity[0],
                       velocity[1], velocity[2]);
}

/*
 * A sequence of stamps (any numbers) as a new array of doubles (PyMem_Free it), its length in
 * *n; NULL with an exception (not a sequence, an item not a number, no memory).
 */
static double *read_stamps(PyObject *o, Py_ssize_t *n)
{
  PyObject *times = PySequence_Fast(o, "times must be a sequence");
  if (times == NULL) {
    return NULL;
  }
  *n = PySequence_Fast_GET_SIZE(times);
  double *t = PyMem_Malloc(sizeof(double) * (size_t)(*n > 0 ? *n : 1));
  if (t == NULL) {
    PyErr_NoMemory();
  } else {
    for (Py_ssize_t i = 0; i < *n; i++) {
      t[i] = item_double(PySequence_Fast_GET_ITEM(times, i));
    }
    if (PyErr_Occurred()) {
      PyMem_Free(t);
      t = NULL;
    }
  }
  Py_DECREF(times);
  return t;
}

/*
 * third_jumps(times) -> bytes: the (n - 4) x n matrix J (row-major doubles, per s^3) whose
 * product with values gives the not-a-knot interpolant's third-derivative jumps at the inner
 * knots 2..n-3 (core.motion.smoothing.third_jumps): the slopes of each unit value's spline
 * (not_a_knot_solve on the identity), each piece's third derivative 6 (s0 + s1 - 2 chord) / h^2
 * in numpy's order of operations, and the differences of consecutive pieces'. ValueError:
 * fewer than 5 stamps.
 */
/* the (n - 4) x n third-jump rows of stamps t (third_jumps' comment) into jumps, n >= 5; false
 * with MemoryError */
static bool third_jump_rows(const double *t, Py_ssize_t n, double *jumps)
{
  double *memory = PyMem_Malloc(sizeof(double) * (size_t)(n * (7 + 3 * n)));
  if (memory == NULL) {
    PyErr_NoMemory();
    return false;
  }
  double *basis = memory, *slopes = basis + n * n, *third = slopes + n * n;
  double *work = third + n * n; /* 6 n */
  double *h = work + 6 * n;     /* n - 1 */
  for (Py_ssize_t i = 0; i < n * n; i++) {
    basis[i] = 0.0;
  }
  for (Py_ssize_t i = 0; i < n; i++) {
    basis[i * n + i] = 1.0;
  }
  not_a_knot_solve(t, n, basis, n, 0, slopes, work);
  for (Py_ssize_t i = 0; i < n - 1; i++) {
    h[i] = t[i + 1] - t[i];
  }
  for (Py_ssize_t i = 0; i < n - 1; i++) { /* piece i's third derivative per unit value c */
    double hh = h[i] * h[i];
    for (Py_ssize_t c = 0; c < n; c++) {
      double chord = (basis[(i + 1) * n + c] - basis[i * n + c]) / h[i];
      third[i * n + c] = 6.0 * (slopes[i * n + c] + slopes[(i + 1) * n + c] - 2.0 * chord) / hh;
    }
  }
  for (Py_ssize_t r = 0; r < n - 4; r++) { /* the jump at knot r + 2 */
    for (Py_ssize_t c = 0; c < n; c++) {
      jumps[r * n + c] = third[(r + 2) * n + c] - third[(r + 1) * n + c];
    }
  }
  PyMem_Free(memory);
  return true;
}

static PyObject *py_third_jumps(PyObject *self, PyObject *arg)
{
  Py_ssize_t n;
  double *t = read_stamps(arg, &n);
  PyObject *result = NULL;
  if (t == NULL) {
    return NULL;
  }
  if (n < 5) {
    PyErr_SetString(PyExc_ValueError, "third_jumps: at least 5 stamps");
  } else {
    result = PyBytes_FromStringAndSize(NULL, (Py_ssize_t)sizeof(double) * (n - 4) * n);
    if (result != NULL && !third_jump_rows(t, n, (double *)PyBytes_AS_STRING(result))) {
      Py_CLEAR(result);
    }
  }
  PyMem_Free(t);
  return result;
}

/*
 * polynomial_basis(times, count) -> bytes: an orthonormal basis (n x count, row-major doubles)
 * of the polynomials of degree < count at the stamps (core.motion.smoothing: a penalty's null
 * space): the powers of the stamps centred on their mean and scaled to [-1, 1], each
 * orthogonalised against the ones before twice (modified Gram-Schmidt, re-orthogonalised) and
 * normalised. ValueError: count not in 1..n, or stamps all equal.
 */
/* polynomial_basis' columns of stamps t (centred here) into q (n x count); false with a
 * ValueError (stamps all equal, count > 1) */
static bool polynomial_columns(double *t, Py_ssize_t n, Py_ssize_t count, double *q)
{
  double mean = 0.0, reach = 0.0;
  for (Py_ssize_t i = 0; i < n; i++) {
    mean += t[i];
  }
  mean /= (double)n;
  for (Py_ssize_t i = 0; i < n; i++) {
    t[i] -= mean;
    reach = max_of(reach, fabs(t[i]));
  }
  if (!(reach > 0.0) && count > 1) {
    PyErr_SetString(PyExc_ValueError, "polynomial_basis: the stamps are all equal");
    return false;
  }
  for (Py_ssize_t c = 0; c < count; c++) {
    for (Py_ssize_t i = 0; i < n; i++) { /* the power c of the scaled stamp */
      q[i * count + c] = c == 0 ? 1.0 : pow(t[i] / reach, (double)c);
    }
    for (int pass = 0; pass < 2; pass++) {
      for (Py_ssize_t b = 0; b < c; b++) {
        double along = 0.0;
        for (Py_ssize_t i = 0; i < n; i++) {
          along += q[i * count + b] * q[i * count + c];
        }
        for (Py_ssize_t i = 0; i < n; i++) {
          q[i * count + c] -= along * q[i * count + b];
        }
      }
    }
    double size = 0.0;
    for (Py_ssize_t i = 0; i < n; i++) {
      size += q[i * count + c] * q[i * count + c];
    }
    size = sqrt(size);
    for (Py_ssize_t i = 0; i < n; i++) {
      q[i * count + c] /= size;
    }
  }
  return true;
}

static PyObject *py_polynomial_basis(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t count;
  if (nargs != 2 || !read_index(args[1], &count)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "polynomial_basis(times, count)");
    }
    return NULL;
  }
  Py_ssize_t n;
  double *t = read_stamps(args[0], &n);
  PyObject *result = NULL;
  if (t == NULL) {
    return NULL;
  }
  if (count < 1 || count > n) {
    PyErr_SetString(PyExc_ValueError, "polynomial_basis: 1 <= count <= the stamps");
  } else {
    result = PyBytes_FromStringAndSize(NULL, (Py_ssize_t)sizeof(double) * n * count);
    if (result != NULL && !polynomial_columns(t, n, count, (double *)PyBytes_AS_STRING(result))) {
      Py_CLEAR(result);
    }
  }
  PyMem_Free(t);
  return result;
}

/*
 * step_key(times) -> bytes or None: a window's steps to the nanosecond (n - 1 doubles, each
 * rint((t[i + 1] - t[i]) * 1e9), numpy's order), the key a penalty is kept by
 * (core.motion.smoothing.penalty_eigen); None with fewer than 2 stamps or a step under 1 ns
 * (or not a number).
 */
static PyObject *py_step_key(PyObject *self, PyObject *arg)
{
  Py_ssize_t n;
  double *t = read_stamps(arg, &n);
  if (t == NULL) {
    return NULL;
  }
  PyObject *result = NULL;
  bool whole = n >= 2;
  for (Py_ssize_t i = 0; whole && i < n - 1; i++) {
    t[i] = rint((t[i + 1] - t[i]) * 1e9);
    whole = t[i] >= 1.0;
  }
  result = whole ? PyBytes_FromStringAndSize((const char *)t,
                                             (Py_ssize_t)sizeof(double) * (n - 1))
                 : Py_NewRef(Py_None);
  PyMem_Free(t);
  return result;
}

/*
 * not_a_knot_penalty(times) -> bytes: the not-a-knot roughness penalty P (n x n, row-major,
 * dimensionless; core.motion.smoothing.penalty): with J the third-jump rows (third_jumps) and
 * m the mean step, (m^3 J)^T (m^3 J); zeros below 5 stamps.
 */
static PyObject *py_not_a_knot_penalty(PyObject *self, PyObject *arg)
{
  Py_ssize_t n;
  double *t = read_stamps(arg, &n), *jumps = NULL;
  if (t == NULL) {
    return NULL;
  }
  PyObject *result = PyBytes_FromStringAndSize(NULL, (Py_ssize_t)sizeof(double) * n * n);
  if (result == NULL) {
    goto done;
  }
  double *penalty = (double *)PyBytes_AS_STRING(result);
  memset(penalty, 0, sizeof(double) * (size_t)(n * n));
  if (n < 5) {
    goto done;
  }
  jumps = PyMem_Malloc(sizeof(double) * (size_t)((n - 4) * n));
  if (jumps == NULL) {
    PyErr_NoMemory();
    Py_CLEAR(result);
    goto done;
  }
  if (!third_jump_rows(t, n, jumps)) {
    Py_CLEAR(result);
    goto done;
  }
  double mean = 0.0;
  for (Py_ssize_t i = 0; i < n - 1; i++) {
    mean += t[i + 1] - t[i];
  }
  double scale = pow(mean / (double)(n - 1), 3.0);
  for (Py_ssize_t i = 0; i < (n - 4) * n; i++) {
    jumps[i] *= scale;
  }
  /* the upper triangle row by row of J, each entry's sum in the order of the rows (its terms
   * independent of one another's: no chain of additions waiting on the one before), then
   * mirrored */
  for (Py_ssize_t r = 0; r < n - 4; r++) {
    const double *row = jumps + r * n;
    for (Py_ssize_t a = 0; a < n; a++) {
      double left = row[a];
      double *out = penalty + a * n;
      for (Py_ssize_t b = a; b < n; b++) {
        out[b] += left * row[b];
      }
    }
  }
  for (Py_ssize_t a = 0; a < n; a++) {
    for (Py_ssize_t b = a + 1; b < n; b++) {
      penalty[b * n + a] = penalty[a * n + b];
    }
  }
done:
  PyMem_Free(jumps);
  PyMem_Free(t);
  return result;
}

/*
 * beside_null(p, u, times, count, null_eigenvalue) -> float: a penalty's eigenvalues p (n,
 * ascending) and eigenvectors u (n x n, row-major, one per column), both writable, given their
 * null space exactly (core.motion.smoothing._eigen_beside_null): u's first ``count`` columns
 * become polynomial_basis(times, count), the others less their parts in it, p's first count
 * zero and any at most null_eigenvalue times the largest zero. Returns the largest squared
 * norm of a column's removed parts (columns orthonormal before are off orthonormal by at most
 * it). ValueError: arrays of the wrong shapes, count not in 1..n, stamps all equal.
 */
static PyObject *py_beside_null(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t count;
  double null_eigenvalue;
  if (nargs != 5 || !read_index(args[3], &count) || !read_number(args[4], &null_eigenvalue)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "beside_null(p, u, times, count, null_eigenvalue)");
    }
    return NULL;
  }
  Py_ssize_t n;
  double *t = read_stamps(args[2], &n), *basis = NULL;
  if (t == NULL) {
    return NULL;
  }
  PyObject *result = NULL;
  Py_buffer values, vectors;
  bool have_values = false, have_vectors = false;
  if (count < 1 || count > n) {
    PyErr_SetString(PyExc_ValueError, "beside_null: 1 <= count <= the stamps");
    goto done;
  }
  if (!(have_values = get_buffer(args[0], &values, n, true)) ||
      !(have_vectors = get_buffer(args[1], &vectors, n * n, true))) {
    goto done;
  }
  basis = PyMem_Malloc(sizeof(double) * (size_t)(n * count + count));
  if (basis == NULL) {
    PyErr_NoMemory();
    goto done;
  }
  double *part = basis + n * count;
  if (!polynomial_columns(t, n, count, basis)) {
    goto done;
  }
  double *p = values.buf, *u = vectors.buf, leak = 0.0;
  for (Py_ssize_t j = count; j < n; j++) {
    double size = 0.0;
    for (Py_ssize_t b = 0; b < count; b++) {
      double along = 0.0;
      for (Py_ssize_t i = 0; i < n; i++) {
        along += basis[i * count + b] * u[i * n + j];
      }
      part[b] = along;
      size += along * along;
    }
    for (Py_ssize_t i = 0; i < n; i++) {
      double off = 0.0;
      for (Py_ssize_t b = 0; b < count; b++) {
        off += basis[i * count + b] * part[b];
      }
      u[i * n + j] -= off;
    }
    leak = max_of(leak, size);
  }
  for (Py_ssize_t i = 0; i < n; i++) {
    for (Py_ssize_t b = 0; b < count; b++) {
      u[i * n + b] = basis[i * count + b];
    }
  }
  for (Py_ssize_t b = 0; b < count; b++) {
    p[b] = 0.0;
  }
  double floor = null_eigenvalue * p[n - 1];
  for (Py_ssize_t i = 0; i < n; i++) {
    if (p[i] <= floor) {
      p[i] = 0.0;
    }
  }
  result = PyFloat_FromDouble(leak);
done:
  if (have_values) {
    PyBuffer_Release(&values);
  }
  if (have_vectors) {
    PyBuffer_Release(&vectors);
  }
  PyMem_Free(basis);
  PyMem_Free(t);
  return result;
}

/*
 * count contiguous float64 buffers, args[positions[i]] into views[i] and their lengths (in
 * doubles) into counts[i]; false with an exception (and none held) where one is not such a
 * buffer. Release them with release_views.
 */
static bool get_views(PyObject *const *args, const int *positions, int count,
                      const char *const *names, Py_buffer *views, Py_ssize_t *counts)
{
  for (int held = 0; held < count; held++) {
    if (!get_doubles(args[positions[held]], &views[held], &counts[held], names[held], false)) {
      while (held > 0) {
        PyBuffer_Release(&views[--held]);
      }
      return false;
    }
  }
  return true;
}

static void release_views(Py_buffer *views, int count)
{
  for (int i = 0; i < count; i++) {
    PyBuffer_Release(&views[i]);
  }
}

/* a group's (start, stop) columns, 0 <= start <= stop <= c; false with a ValueError */
static bool read_bound(PyObject *o, Py_ssize_t c, Py_ssize_t *start, Py_ssize_t *stop)
{
  *start = *stop = -1;
  PyObject *pair = PySequence_Fast(o, "a bound");
  if (pair != NULL && PySequence_Fast_GET_SIZE(pair) == 2) {
    *start = PyNumber_AsSsize_t(PySequence_Fast_GET_ITEM(pair, 0), NULL);
    *stop = PyNumber_AsSsize_t(PySequence_Fast_GET_ITEM(pair, 1), NULL);
  }
  Py_XDECREF(pair);
  if (PyErr_Occurred() || *start < 0 || *stop > c || *start > *stop) {
    PyErr_Clear();
    PyErr_SetString(PyExc_ValueError, "bounds must be (start, stop) columns");
    return false;
  }
  return true;
}

/* x scaled into [0.5, 1) with its power of two added to *exponent (a product kept in range) */
enum { LANES = 4 }; /* likeliest's grid weights taken at a time */

static inline double renormalised(double x, long *exponent)
{
  int e;
  double m = frexp(x, &e);
  *exponent += e;
  return m;
}

enum { LIKELIHOOD_STRIDE = 16 }; /* likeliest's first weights: every 16th of the grid */
#define LIKELIHOOD_SLACK 1e-10      /* its bounds' allowance for rounding, of their terms' size */

/*
 * likeliest's costs of the grid weights which[0 .. count): point_logs[g] the log part
 * sum_i log(1 + 1 / (lam p_i)) (a group's cost has k times it), point_sums[k * points + g]
 * group k's sum_i s_i / (1 + 1 / (lam p_i)). LANES weights at a time, each lane's numbers by
 * the operations of its weight alone (its product and sums in the order of the eigenvalues),
 * so a weight's numbers are the same whichever others it is taken with; the lanes' chains of
 * products and sums are independent, so they overlap. shrink: LANES x n scratch.
 */
static void likeliest_costs(const Py_ssize_t *which, Py_ssize_t count, const double *grid,
                            const double *rough, Py_ssize_t m, Py_ssize_t n, double logs_of_p,
                            const double *scaled, Py_ssize_t groups, double *shrink,
                            double *point_logs, double *point_sums, Py_ssize_t points)
{
  for (Py_ssize_t w0 = 0; w0 < count; w0 += LANES) {
    Py_ssize_t lanes = count - w0 < LANES ? count - w0 : LANES;
    double lam[LANES], product[LANES], power[LANES], sum[LANES];
    long exponent[LANES];
    for (Py_ssize_t l = 0; l < LANES; l++) { /* (past the list's end: its last weight again) */
      power[l] = grid[which[w0 + (l < lanes ? l : lanes - 1)]];
      lam[l] = pow(10.0, power[l]);
      product[l] = 1.0;
      exponent[l] = 0;
    }
    for (Py_ssize_t l = 0; l < LANES; l++) { /* (no carried dependency: vectorised) */
      for (Py_ssize_t i = 0; i < m; i++) {
        double x = lam[l] * rough[i];
        shrink[l * n + i] = x / (1.0 + x);
      }
    }
    for (Py_ssize_t i = 0; i < m; i++) {
      for (Py_ssize_t l = 0; l < LANES; l++) {
        product[l] *= 1.0 + lam[l] * rough[i];
      }
      for (Py_ssize_t l = 0; l < LANES; l++) {
        if (!(product[l] < 1e150)) {
          product[l] = renormalised(product[l], &exponent[l]);
        }
      }
    }
    for (Py_ssize_t l = 0; l < lanes; l++) {
      point_logs[which[w0 + l]] = log(product[l]) + (double)exponent[l] * M_LN2 -
                                  (double)m * power[l] * M_LN10 - logs_of_p;
    }
    for (Py_ssize_t k = 0; k < groups; k++) {
      for (Py_ssize_t l = 0; l < LANES; l++) {
        sum[l] = 0.0;
      }
      for (Py_ssize_t i = 0; i < m; i++) {
        for (Py_ssize_t l = 0; l < LANES; l++) {
          sum[l] += shrink[l * n + i] * scaled[k * n + i];
        }
      }
      for (Py_ssize_t l = 0; l < lanes; l++) {
        point_sums[k * points + which[w0 + l]] = sum[l];
      }
    }
  }
}

/*
 * likeliest(p, z, variances, bounds, grid, null_eigenvalue) -> a tuple of weights, one per
 * group of columns: the smoothing weight of largest marginal likelihood
 * (core.motion.smoothing.smoothing_weight with target 'likelihood': the module docstring
 * there). p: the penalty's n eigenvalues (>= 0); z: the values in its eigenvectors (n x c,
 * row-major); variances: the c columns' noise variances; bounds: (start, stop) column ranges,
 * the groups, each with one weight; grid: the log10 weights searched.
 *
 * The eigenvalues above null_eigenvalue times the largest count (the rough ones; the null
 * space drops out, as in REML). For a group's noisy columns (variance > 0), with s_i the sum of
 * z_i^2 / variance over them and k their count, each grid weight lam costs
 *   k sum_i log(1 + 1 / (lam p_i)) + sum_i s_i / (1 + 1 / (lam p_i))
 * over the rough i (the negative log-likelihood of z under the prior's variances
 * sigma^2 (1 + 1 / (lam p_i)), constants dropped); the first smallest cost is taken
 * (numpy.argmin's rule, a NaN first), found by bounds without costing every weight (below: the
 * same weight as the whole grid's, to the bit). The sum of logs is taken as the log of a
 * product of the factors 1 + lam p_i (kept in range by its power of two) less m log(lam) and
 * the sum of log(p_i): one log a grid weight, not one a term. A group's weight: 10^grid[best];
 * inf where best is the grid's last (the stiffest fit: the null space's projection); NaN where
 * no column is noisy or no eigenvalue is positive (nothing to smooth). ValueError: buffers of
 * the wrong type or shapes, bounds outside the columns.
 */
static PyObject *py_likeliest(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  double null_eigenvalue;
  if (nargs != 6 || !read_number(args[5], &null_eigenvalue)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError,
                      "likeliest(p, z, variances, bounds, grid, null_eigenvalue)");
    }
    return NULL;
  }
  Py_buffer views[4];
  Py_ssize_t counts[4];
  static const char *const names[4] = {"likeliest: p", "likeliest: z", "likeliest: variances",
                                       "likeliest: grid"};
  static const int positions[4] = {0, 1, 2, 4};
  if (!get_views(args, positions, 4, names, views, counts)) {
    return NULL;
  }
  PyObject *result = NULL, *bounds = NULL;
  double *memory = NULL;
  const double *p = views[0].buf, *z = views[1].buf, *variances = views[2].buf;
  const double *grid = views[3].buf;
  Py_ssize_t n = counts[0], c = counts[2], points = counts[3];
  if (counts[1] != n * c || points < 1) {
    PyErr_SetString(PyExc_ValueError, "likeliest: z must be n x c, the grid not empty");
    goto done;
  }
  bounds = PySequence_Fast(args[3], "likeliest: bounds must be a sequence");
  if (bounds == NULL) {
    goto done;
  }
  Py_ssize_t groups = PySequence_Fast_GET_SIZE(bounds);
  memory = PyMem_Malloc(sizeof(double) *
                        (size_t)(n * (groups + 1 + LANES) + groups + 1));
  if (memory == NULL) {
    PyErr_NoMemory();
    goto done;
  }
  double *rough = memory;                 /* the rough eigenvalues, m of them */
  double *scaled = rough + n;             /* per group, its s_i over the rough i (m each) */
  double *shrink = scaled + n * groups;   /* per lane, its weight's 1 / (1 + 1 / (lam p_i)) */
  double *best_cost = shrink + n * LANES; /* per group, the lowest so far */
  Py_ssize_t *best = NULL, *noisy = NULL;
  double largest = 1e-300;
  for (Py_ssize_t i = 0; i < n; i++) {
    largest = max_of(largest, p[i]);
  }
  Py_ssize_t m = 0;
  for (Py_ssize_t i = 0; i < n; i++) {
    if (p[i] > null_eigenvalue * largest) {
      rough[m++] = p[i];
    }
  }
  best = PyMem_Malloc(sizeof(Py_ssize_t) * (size_t)(2 * groups + 1));
  if (best == NULL) {
    PyErr_NoMemory();
    goto done;
  }
  noisy = best + groups;
  for (Py_ssize_t k = 0; k < groups; k++) {
    Py_ssize_t start, stop;
    if (!read_bound(PySequence_Fast_GET_ITEM(bounds, k), c, &start, &stop)) {
      PyMem_Free(best);
      goto done;
    }
    noisy[k] = 0;
    for (Py_ssize_t j = start; j < stop; j++) {
      noisy[k] += variances[j] > 0.0;
    }
    Py_ssize_t r = 0;
    for (Py_ssize_t i = 0; i < n; i++) { /* the rough rows, in order */
      if (!(p[i] > null_eigenvalue * largest)) {
        continue;
      }
      double sum = 0.0;
      for (Py_ssize_t j = start; j < stop; j++) {
        if (variances[j] > 0.0) {
          sum += z[i * c + j] * z[i * c + j] / variances[j];
        }
      }
      scaled[k * n + r++] = sum;
    }
    best[k] = -1;
  }
  /* sum_i log(1 + 1 / (lam p_i)) = sum_i log(1 + lam p_i) - m log(lam) - sum_i log(p_i): the
   * last is the window's, the first the log of a product of factors >= 1 */
  double logs_of_p = 0.0;
  for (Py_ssize_t i = 0; i < m; i++) {
    logs_of_p += log(rough[i]);
  }
  /* The costs searched by bounds, each weight costed as it would be alone
   * (likeliest_costs): every LIKELIHOOD_STRIDE-th weight and the last first. Between two of
   * them a group's cost is at least its log part at the upper (the part falls as the weight
   * grows) plus its sum at the lower (the sum rises): a stretch whose bound is above every
   * group's cheapest so far by more than LIKELIHOOD_SLACK of its terms (rounding) holds no
   * weight as cheap and is left uncosted; the others are costed. The first smallest cost in the
   * grid's order is then the one a search of the whole grid finds (numpy.argmin's rule); a
   * cost or a bound that is not finite costs the whole grid. */
  Py_ssize_t *coarse = NULL, *more = NULL, coarse_count = 0, more_count = 0;
  double *point_logs = NULL, *point_sums = NULL; /* per weight; per group and weight */
  unsigned char *wanted = NULL;
  if (m > 0) {
    coarse = PyMem_Malloc(sizeof(Py_ssize_t) * (size_t)(2 * points));
    point_logs = PyMem_Malloc(sizeof(double) * (size_t)(points * (groups + 1)));
    wanted = PyMem_Calloc((size_t)points, 1);
    if (coarse == NULL || point_logs == NULL || wanted == NULL) {
      PyErr_NoMemory();
      goto searched;
    }
    more = coarse + points;
    point_sums = point_logs + points;
    for (Py_ssize_t g = 0; g < points; g += LIKELIHOOD_STRIDE) {
      coarse[coarse_count++] = g;
    }
    if (coarse[coarse_count - 1] != points - 1) {
      coarse[coarse_count++] = points - 1;
    }
    likeliest_costs(coarse, coarse_count, grid, rough, m, n, logs_of_p, scaled, groups, shrink,
                    point_logs, point_sums, points);
  }
  bool whole = false;
  for (Py_ssize_t k = 0; k < groups && m > 0 && !whole; k++) {
    if (noisy[k] == 0) {
      continue;
    }
    double lowest = INFINITY;
    for (Py_ssize_t c = 0; c < coarse_count; c++) {
      double here = (double)noisy[k] * point_logs[coarse[c]] + point_sums[k * points + coarse[c]];
      whole = whole || !isfinite(here);
      lowest = min_of(lowest, here);
    }
    for (Py_ssize_t c = 0; c + 1 < coarse_count && !whole; c++) {
      Py_ssize_t a = coarse[c], b = coarse[c + 1];
      double falling = (double)noisy[k] * point_logs[b], rising = point_sums[k * points + a];
      double slack = LIKELIHOOD_SLACK *
                     (1.0 + fabs(lowest) + fabs(falling) + fabs(rising) +
                      (double)noisy[k] * (fabs((double)m * grid[b] * M_LN10) + fabs(logs_of_p)));
      whole = whole || !isfinite(falling + rising);
      if (!(falling + rising > lowest + slack)) {
        memset(wanted + a + 1, 1, (size_t)(b - a - 1));
      }
    }
  }
  for (Py_ssize_t c = 0; c + 1 < coarse_count; c++) {
    for (Py_ssize_t g = coarse[c] + 1; g < coarse[c + 1]; g++) {
      if (whole || wanted[g]) {
        more[more_count++] = g;
      }
    }
  }
  if (more_count > 0) {
    likeliest_costs(more, more_count, grid, rough, m, n, logs_of_p, scaled, groups, shrink,
                    point_logs, point_sums, points);
  }
  /* the costed weights in the grid's order (the two ascending lists merged) */
  for (Py_ssize_t c = 0, d = 0; c < coarse_count || d < more_count;) {
    Py_ssize_t g = d >= more_count || (c < coarse_count && coarse[c] < more[d]) ? coarse[c++]
                                                                               : more[d++];
    for (Py_ssize_t k = 0; k < groups; k++) {
      if (noisy[k] == 0 || (best[k] >= 0 && isnan(best_cost[k]))) {
        continue;
      }
      double here = (double)noisy[k] * point_logs[g] + point_sums[k * points + g];
      if (best[k] < 0 || isnan(here) || here < best_cost[k]) {
        best[k] = g;
        best_cost[k] = here;
      }
    }
  }
  result = PyTuple_New(groups);
  for (Py_ssize_t k = 0; result != NULL && k < groups; k++) {
    double weight = noisy[k] == 0 || m == 0 ? NAN
                    : best[k] == points - 1 ? INFINITY
                    : pow(10.0, grid[best[k]]);
    PyObject *item = PyFloat_FromDouble(weight);
    if (item == NULL) {
      Py_CLEAR(result);
      break;
    }
    PyTuple_SET_ITEM(result, k, item);
  }
searched:
  PyMem_Free(coarse);
  PyMem_Free(point_logs);
  PyMem_Free(wanted);
  PyMem_Free(best);
done:
  PyMem_Free(memory);
  Py_XDECREF(bounds);
  release_views(views, 4);
  return result;
}

/*
 * smoothed(p, u, z, y, variances, bounds, weights, null_eigenvalue) -> bytearray: a window's
 * smoothed values (n x c, row-major doubles; core.motion.smoothing.smooth). p: the penalty's n
 * eigenvalues; u: its eigenvectors (n x n, row-major, one per column); z = u^T y (n x c);
 * y: the values (n x c); variances: the c columns' noise variances; bounds: (start, stop)
 * column ranges, the groups; weights: one per group (likeliest's or another rule's). A group's
 * columns become u (f z) with f_i = 1 / (1 + lam p_i), or at lam = inf 1 on the null space
 * (p_i <= null_eigenvalue times the largest) and 0 off it; a group of weight NaN, and every
 * column of zero variance, keep y. ValueError: buffers of the wrong type or shapes, bounds
 * outside the columns, a weights sequence not as long as the bounds.
 */
static PyObject *py_smoothed(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  double null_eigenvalue;
  if (nargs != 8 || !read_number(args[7], &null_eigenvalue)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError,
                      "smoothed(p, u, z, y, variances, bounds, weights, null_eigenvalue)");
    }
    return NULL;
  }
  Py_buffer views[5];
  Py_ssize_t counts[5];
  static const char *const names[5] = {"smoothed: p", "smoothed: u", "smoothed: z",
                                       "smoothed: y", "smoothed: variances"};
  static const int positions[5] = {0, 1, 2, 3, 4};
  if (!get_views(args, positions, 5, names, views, counts)) {
    return NULL;
  }
  PyObject *result = NULL, *bounds = NULL, *weights = NULL;
  double *factor = NULL;
  const double *p = views[0].buf, *u = views[1].buf, *z = views[2].buf, *y = views[3].buf;
  const double *variances = views[4].buf;
  Py_ssize_t n = counts[0], c = counts[4];
  if (counts[1] != n * n || counts[2] != n * c || counts[3] != n * c) {
    PyErr_SetString(PyExc_ValueError, "smoothed: u must be n x n, z and y n x c");
    goto done;
  }
  bounds = PySequence_Fast(args[5], "smoothed: bounds must be a sequence");
  weights = bounds ? PySequence_Fast(args[6], "smoothed: weights must be a sequence") : NULL;
  if (weights == NULL) {
    goto done;
  }
  Py_ssize_t groups = PySequence_Fast_GET_SIZE(bounds);
  if (PySequence_Fast_GET_SIZE(weights) != groups) {
    PyErr_SetString(PyExc_ValueError, "smoothed: one weight per group");
    goto done;
  }
  factor = PyMem_Malloc(sizeof(double) * (size_t)(n * (c + 1) + 1));
  if (factor == NULL) {
    PyErr_NoMemory();
    goto done;
  }
  double *scaled = factor + n; /* f_i z_i,j */
  result = PyByteArray_FromStringAndSize(NULL, (Py_ssize_t)sizeof(double) * n * c);
  if (result == NULL) {
    goto done;
  }
  double *out = (double *)PyByteArray_AS_STRING(result);
  memcpy(out, y, sizeof(double) * (size_t)(n * c));
  double largest = 0.0;
  for (Py_ssize_t i = 0; i < n; i++) {
    largest = max_of(largest, p[i]);
  }
  for (Py_ssize_t k = 0; k < groups; k++) {
    Py_ssize_t start, stop;
    if (!read_bound(PySequence_Fast_GET_ITEM(bounds, k), c, &start, &stop)) {
      Py_CLEAR(result);
      goto done;
    }
    double lam = PyFloat_AsDouble(PySequence_Fast_GET_ITEM(weights, k));
    if (PyErr_Occurred()) {
      Py_CLEAR(result);
      goto done;
    }
    if (isnan(lam)) {
      continue;
    }
    for (Py_ssize_t i = 0; i < n; i++) {
      factor[i] = isinf(lam) ? (p[i] <= null_eigenvalue * largest ? 1.0 : 0.0)
                             : 1.0 / (1.0 + lam * p[i]);
    }
    for (Py_ssize_t j = start; j < stop; j++) {
      if (!(variances[j] > 0.0)) {
        continue;
      }
      for (Py_ssize_t i = 0; i < n; i++) {
        scaled[i] = factor[i] * z[i * c + j];
      }
      for (Py_ssize_t r = 0; r < n; r++) {
        double sum = 0.0;
        for (Py_ssize_t i = 0; i < n; i++) {
          sum += u[r * n + i] * scaled[i];
        }
        out[r * c + j] = sum;
      }
    }
  }
done:
  PyMem_Free(factor);
  Py_XDECREF(bounds);
  Py_XDECREF(weights);
  release_views(views, 5);
  return result;
}

/*
 * A bat sample's knob and tip (m), and the objects they were read from (new references in
 * *knob_object and *tip_object, or NULL: the caller releases them). False with an exception
 * (no knob or tip of 3 numbers).
 */
static bool bat_ends(PyObject *sample, Vec *knob, Vec *tip, PyObject **knob_object,
                     PyObject **tip_object)
{
  *knob_object = PyObject_GetAttr(sample, knob_name);
  *tip_object = *knob_object ? PyObject_GetAttr(sample, tip_name) : NULL;
  if (*tip_object == NULL) {
    return false;
  }
  if (!read_vec(*knob_object, knob) || !read_vec(*tip_object, tip)) {
    PyErr_SetString(PyExc_TypeError, "a bat sample's knob and tip must be 3 numbers each");
    return false;
  }
  return true;
}

/* math.dist(a, b) as a double (NAN with an exception) */
static double python_dist(PyObject *a, PyObject *b)
{
  PyObject *dist = PyObject_CallFunctionObjArgs(math_dist, a, b, NULL);
  double x = dist ? PyFloat_AsDouble(dist) : NAN;
  Py_XDECREF(dist);
  return x;
}

/*
 * The unit knob-to-tip direction ((tip - knob) over the square root of its summed squares,
 * geometry.norm) and the length (m, math.dist of the objects the ends were read from) of a
 * bat's ends. False with an exception.
 */
static bool ends_axis(Vec knob, Vec tip, PyObject *knob_object, PyObject *tip_object,
                      Vec *direction, double *length)
{
  Vec axis = v_sub(tip, knob);
  double size = sqrt(axis.x * axis.x + axis.y * axis.y + axis.z * axis.z);
  *direction = (Vec){axis.x / size, axis.y / size, axis.z / size};
  *length = python_dist(tip_object, knob_object);
  return !PyErr_Occurred();
}

/*
 * A bat sample's knob (m), unit knob-to-tip direction and length (m): ``ends_axis`` of its
 * ends. False with an exception (no knob or tip of 3 numbers).
 */
static bool bat_axis(PyObject *sample, Vec *knob, Vec *direction, double *length)
{
  PyObject *knob_object = NULL, *tip_object = NULL;
  Vec tip;
  bool ok = bat_ends(sample, knob, &tip, &knob_object, &tip_object) &&
            ends_axis(*knob, tip, knob_object, tip_object, direction, length);
  Py_XDECREF(knob_object);
  Py_XDECREF(tip_object);
  return ok;
}

/* the rotation vector (rad, across reference) turning unit reference onto unit direction */
static Vec rotation_to(Vec r, Vec d)
{
  Vec t = {r.y * d.z - r.z * d.y, r.z * d.x - r.x * d.z, r.x * d.y - r.y * d.x};
  double sine = sqrt(t.x * t.x + t.y * t.y + t.z * t.z);
  if (sine < 1e-15) {
    return (Vec){0.0, 0.0, 0.0};
  }
  double angle = atan2(sine, r.x * d.x + r.y * d.y + r.z * d.z) / sine;
  return (Vec){t.x * angle, t.y * angle, t.z * angle};
}

/* reference turned by a rotation vector across it (Rodrigues; core.motion.c2.rotate, its
 * operations in its order); *same true (and the result reference) below 1e-15 rad */
static Vec rotate_by(Vec f, Vec r, bool *same)
{
  double angle = sqrt(r.x * r.x + r.y * r.y + r.z * r.z);
  *same = angle < 1e-15;
  if (*same) {
    return f;
  }
  Vec across = {r.y * f.z - r.z * f.y, r.z * f.x - r.x * f.z, r.x * f.y - r.y * f.x};
  double c = cos(angle), s = sin(angle) / angle;
  return (Vec){c * f.x + s * across.x, c * f.y + s * across.y, c * f.z + s * across.z};
}

/* rotate(reference, rotation) -> reference turned by the rotation vector (the same object
 * below 1e-15 rad) */
static PyObject *py_rotate(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Vec reference, rotation;
  if (nargs != 2 || !read_vec(args[0], &reference) || !read_vec(args[1], &rotation)) {
    PyErr_SetString(PyExc_TypeError, "rotate(reference, rotation): two 3-vectors");
    return NULL;
  }
  bool same;
  Vec turned = rotate_by(reference, rotation, &same);
  return same ? Py_NewRef(args[0]) : vec_tuple(turned);
}

/*
 * A bat sample's knob, tip and quaternion (x, y, z, w; *posed false when the sample's quaternion
 * is None). False with an exception (no knob or tip of 3 numbers, a quaternion not None nor 4
 * numbers).
 */
static bool bat_pose_parts(PyObject *sample, Vec *knob, Vec *tip, double quaternion[4],
                           bool *posed)
{
  PyObject *knob_object = NULL, *tip_object = NULL, *quaternion_object = NULL;
  bool ok = bat_ends(sample, knob, tip, &knob_object, &tip_object) &&
            (quaternion_object = PyObject_GetAttr(sample, quaternion_name)) != NULL;
  if (ok) {
    *posed = quaternion_object != Py_None;
    ok = !*posed || read_floats(quaternion_object, quaternion, 4, "a bat sample's quaternion");
  }
  Py_XDECREF(knob_object);
  Py_XDECREF(tip_object);
  Py_XDECREF(quaternion_object);
  return ok;
}

/*
 * A bat sample's knob-to-tip vector (tip - knob, m) and its quaternion (x, y, z, w; *posed
 * false when the sample's quaternion is None). False with an exception (no knob or tip of 3
 * numbers, a quaternion not None nor 4 numbers).
 */
static bool bat_turn_parts(PyObject *sample, Vec *axis, double quaternion[4], bool *posed)
{
  Vec knob, tip;
  if (!bat_pose_parts(sample, &knob, &tip, quaternion, posed)) {
    return false;
  }
  *axis = v_sub(tip, knob);
  return true;
}

/*
 * turn_between(a, b) -> ((x, y, z), roll): how the bat turned from sample a to sample b
 * (core.motion.base.turn_between, the docstring there): the swing rotation turning a's
 * knob-to-tip vector d0 onto b's d1 (their cross product times atan2(its norm, d0 . d1) over
 * its norm, zero where the norm is not positive: geometry.swing_rotation), and the roll: the
 * world-frame rotation vector of q1 conj(q0) along the shorter arc (geometry.rotation_between)
 * along the mean axis d0 + d1 (its dot product with it over the axis' norm); 0.0 without both
 * quaternions, when the quaternions are equal up to sign, or when d0 + d1 is zero. Each
 * operation in the order of those functions: the same bits. TypeError: a sample without a
 * knob and tip of 3 numbers, or a quaternion neither None nor 4 numbers.
 */
/*
 * How the bat turned from one pose to the next (turn_between's numbers): d0, d1 the knob-to-tip
 * vectors, q0, q1 the quaternions (x, y, z, w) or NULL (no roll without both).
 */
static void turn_step(Vec d0, const double *q0, Vec d1, const double *q1, Vec *swing_out,
                      double *roll_out)
{
  Vec turn = {d0.y * d1.z - d0.z * d1.y, d0.z * d1.x - d0.x * d1.z, d0.x * d1.y - d0.y * d1.x};
  double sine = sqrt(turn.x * turn.x + turn.y * turn.y + turn.z * turn.z);
  Vec swing = {0.0, 0.0, 0.0};
  if (sine > 0.0) {
    double angle = atan2(sine, d0.x * d1.x + d0.y * d1.y + d0.z * d1.z) / sine;
    swing = (Vec){turn.x * angle, turn.y * angle, turn.z * angle};
  }
  double roll = 0.0;
  if (q0 != NULL && q1 != NULL) {
    double x0 = q0[0], y0 = q0[1], z0 = q0[2], w0 = q0[3];
    double x1 = q1[0], y1 = q1[1], z1 = q1[2], w1 = q1[3];
    double w = w1 * w0 + x1 * x0 + y1 * y0 + z1 * z0;
    double x = -w1 * x0 + x1 * w0 - y1 * z0 + z1 * y0;
    double y = -w1 * y0 + y1 * w0 - z1 * x0 + x1 * z0;
    double z = -w1 * z0 + z1 * w0 - x1 * y0 + y1 * x0;
    if (w < 0.0) {
      w = -w, x = -x, y = -y, z = -z;
    }
    double vector_part = sqrt(x * x + y * y + z * z);
    Vec mean_axis = {d0.x + d1.x, d0.y + d1.y, d0.z + d1.z};
    double length = sqrt(mean_axis.x * mean_axis.x + mean_axis.y * mean_axis.y +
                         mean_axis.z * mean_axis.z);
    if (vector_part != 0.0 && length != 0.0) {
      double angle = 2.0 * atan2(vector_part, w) / vector_part;
      Vec full = {x * angle, y * angle, z * angle};
      roll = (full.x * mean_axis.x + full.y * mean_axis.y + full.z * mean_axis.z) / length;
    }
  }
  *swing_out = swing;
  *roll_out = roll;
}

/* how the bat turned from sample a to sample b (turn_between's numbers); false with an exception */
static bool bat_turn(PyObject *a, PyObject *b, Vec *swing_out, double *roll_out)
{
  Vec d0, d1;
  double q0[4], q1[4];
  bool posed0, posed1;
  if (!bat_turn_parts(a, &d0, q0, &posed0) || !bat_turn_parts(b, &d1, q1, &posed1)) {
    return false;
  }
  turn_step(d0, posed0 && posed1 ? q0 : NULL, d1, posed0 && posed1 ? q1 : NULL, swing_out,
            roll_out);
  return true;
}

static PyObject *py_turn_between(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  if (nargs != 2) {
    PyErr_SetString(PyExc_TypeError, "turn_between(a, b): two bat samples");
    return NULL;
  }
  Vec swing;
  double roll;
  if (!bat_turn(args[0], args[1], &swing, &roll)) {
    return NULL;
  }
  PyObject *swing_tuple = vec_tuple(swing);
  return swing_tuple ? Py_BuildValue("(Nd)", swing_tuple, roll) : NULL;
}

/*
 * fill_turns(values, turns, first_kept, k) -> turns[k]: a bat stream's cumulative turns
 * (core.detector.streams.sum_turns with turn_between's steps, the same sums in the same
 * order): turns (a list of (x, y, z, roll) tuples or None) filled from the last known at or
 * before k; where none is known from first_kept on, turns[first_kept] becomes (0, 0, 0, 0).
 * values: the bat samples (a list as long). IndexError: k outside them.
 */
static PyObject *py_fill_turns(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t first_kept, k;
  if (nargs != 4 || !PyList_Check(args[0]) || !PyList_Check(args[1]) ||
      !read_index(args[2], &first_kept) || !read_index(args[3], &k)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "fill_turns(values, turns, first_kept, k): two lists");
    }
    return NULL;
  }
  PyObject *values = args[0], *turns = args[1];
  Py_ssize_t n = PyList_GET_SIZE(turns);
  if (k < 0 || k >= n || k >= PyList_GET_SIZE(values) || first_kept < 0 || first_kept > k) {
    PyErr_SetString(PyExc_IndexError, "fill_turns: k outside the samples");
    return NULL;
  }
  Py_ssize_t first = k;
  while (PyList_GET_ITEM(turns, first) == Py_None) {
    if (first == first_kept) { /* trimmed past the segment start: a new (zero) reference */
      double zero[4] = {0.0, 0.0, 0.0, 0.0};
      PyObject *reference = float_tuple(zero, 4);
      if (reference == NULL || PyList_SetItem(turns, first, reference) < 0) {
        return NULL;
      }
      break;
    }
    first--;
  }
  double last[4];
  PyObject *known = PyList_GET_ITEM(turns, first);
  if (!PyTuple_Check(known) || PyTuple_GET_SIZE(known) != 4) {
    PyErr_SetString(PyExc_TypeError, "fill_turns: a turn must be 4 numbers");
    return NULL;
  }
  for (int c = 0; c < 4; c++) {
    last[c] = item_double(PyTuple_GET_ITEM(known, c));
  }
  if (PyErr_Occurred()) {
    return NULL;
  }
  for (Py_ssize_t i = first + 1; i <= k; i++) {
    Vec swing;
    double roll;
    if (!bat_turn(PyList_GET_ITEM(values, i - 1), PyList_GET_ITEM(values, i), &swing, &roll)) {
      return NULL;
    }
    last[0] = last[0] + swing.x, last[1] = last[1] + swing.y, last[2] = last[2] + swing.z;
    last[3] = last[3] + roll;
    PyObject *turn = float_tuple(last, 4);
    if (turn == NULL || PyList_SetItem(turns, i, turn) < 0) {
      return NULL;
    }
  }
  return Py_NewRef(PyList_GET_ITEM(turns, k));
}

/*
 * A bat stream's step rows [first, end) made where missing: rows (a list, extended with None
 * up to end) holds, per sample, knob + tip + the turn from the sample before (turn_step; zeros
 * for the stream's first sample), made once (a sample never changes). False with an exception.
 */
static bool fill_step_rows(PyObject *values, PyObject *rows, Py_ssize_t first, Py_ssize_t end)
{
  if (!PyList_Check(values) || !PyList_Check(rows)) {
    PyErr_SetString(PyExc_TypeError, "a bat window's samples and rows must be lists");
    return false;
  }
  if (first < 0 || end <= first || end > PyList_GET_SIZE(values)) {
    PyErr_SetString(PyExc_IndexError, "a bat window is outside its samples");
    return false;
  }
  while (PyList_GET_SIZE(rows) < end) {
    if (PyList_Append(rows, Py_None) < 0) {
      return false;
    }
  }
  Vec knob, tip, before_knob, before_tip;
  double q[4], before_q[4];
  bool posed, before_posed, before_read = false;
  for (Py_ssize_t i = first; i < end; i++) {
    if (PyList_GET_ITEM(rows, i) != Py_None) {
      before_read = false;
      continue;
    }
    if (!bat_pose_parts(PyList_GET_ITEM(values, i), &knob, &tip, q, &posed)) {
      return false;
    }
    Vec swing = {0.0, 0.0, 0.0};
    double roll = 0.0;
    if (i > 0) {
      if (!before_read && !bat_pose_parts(PyList_GET_ITEM(values, i - 1), &before_knob,
                                          &before_tip, before_q, &before_posed)) {
        return false;
      }
      bool both = before_posed && posed;
      turn_step(v_sub(before_tip, before_knob), both ? before_q : NULL, v_sub(tip, knob),
                both ? q : NULL, &swing, &roll);
    }
    double row[BAT_COMPONENTS] = {knob.x, knob.y, knob.z, tip.x,   tip.y,
                                  tip.z,  swing.x, swing.y, swing.z, roll};
    PyObject *made = float_tuple(row, BAT_COMPONENTS);
    if (made == NULL || PyList_SetItem(rows, i, made) < 0) {
      return false;
    }
    before_knob = knob, before_tip = tip, before_posed = posed, before_read = true;
    memcpy(before_q, q, sizeof q);
  }
  return true;
}

/*
 * bat_window_forecast(times, values, rows, first, end, degree) -> the BatForecast's 21 numbers
 * from a bat stream's samples [first, end) (at least 3), or NotImplemented (rank deficient):
 * knob + tip + the turn since the window's first sample (its step rows, fill_step_rows, summed
 * in order), fitted at and extrapolated from the newest (as bat_forecast).
 */
static PyObject *py_bat_window_forecast(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t first, end;
  long degree;
  if (nargs != 6 || !read_index(args[3], &first) || !read_index(args[4], &end) ||
      ((degree = PyLong_AsLong(args[5])) == -1 && PyErr_Occurred())) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError,
                      "bat_window_forecast(times, values, rows, first, end, degree)");
    }
    return NULL;
  }
  if (degree < 0 || degree > MAX_FIT_DEGREE || end - first < 3) {
    PyErr_SetString(PyExc_ValueError,
                    "bat_window_forecast: 0 <= degree <= 15, at least 3 samples");
    return NULL;
  }
  if (!fill_step_rows(args[1], args[2], first, end)) {
    return NULL;
  }
  if (!PyList_Check(args[0]) || end > PyList_GET_SIZE(args[0])) {
    PyErr_SetString(PyExc_IndexError, "a bat window is outside its times");
    return NULL;
  }
  double t = item_double(PyList_GET_ITEM(args[0], end - 1));
  if (t == -1.0 && PyErr_Occurred()) {
    return NULL;
  }
  return bat_window_result(args[0], args[2], first, end, (int)degree, t, true);
}

/*
 * bat_window_rows(values, rows, first, end) -> [knob + tip + turn since sample first, ...]: the
 * rows bat_window_forecast fits (10-tuples; its step rows made where missing)
 */
static PyObject *py_bat_window_rows(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t first, end;
  if (nargs != 4 || !read_index(args[2], &first) || !read_index(args[3], &end)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "bat_window_rows(values, rows, first, end)");
    }
    return NULL;
  }
  if (!fill_step_rows(args[0], args[1], first, end)) {
    return NULL;
  }
  Py_ssize_t n = end - first;
  double *y = PyMem_Malloc(sizeof(double) * (size_t)(n * BAT_COMPONENTS));
  if (y == NULL) {
    return PyErr_NoMemory();
  }
  bool ok = true;
  for (Py_ssize_t i = 0; ok && i < n; i++) {
    PyObject *row = PyList_GET_ITEM(args[1], first + i);
    for (int c = 0; ok && c < BAT_COMPONENTS; c++) {
      y[i * BAT_COMPONENTS + c] = item_double(PyTuple_GET_ITEM(row, c));
      ok = !PyErr_Occurred();
    }
  }
  PyObject *result = NULL;
  if (ok) {
    cumulate_turns(y, n);
    result = PyList_New(n);
    for (Py_ssize_t i = 0; result != NULL && i < n; i++) {
      PyObject *row = float_tuple(y + i * BAT_COMPONENTS, BAT_COMPONENTS);
      if (row == NULL) {
        Py_CLEAR(result);
      } else {
        PyList_SET_ITEM(result, i, row);
      }
    }
  }
  PyMem_Free(y);
  return result;
}

/*
 * A ball window of arrays (forecast_outcomes'): samples first .. first + n - 1 of times and points
 * (m, 3) into x ((time - t0) / span) and y (n x 3), as gather_window makes them of a stream's
 * lists; returns the span (s)
 */
static double ball_array_window(const double *times, const double *points, Py_ssize_t first,
                                Py_ssize_t n, double t0, double *x, double *y)
{
  double span = max_of(t0 - times[first], 1e-9);
  for (Py_ssize_t i = 0; i < n; i++) {
    x[i] = (times[first + i] - t0) / span;
    memcpy(y + 3 * i, points + 3 * (first + i), 3 * sizeof(double));
  }
  return span;
}

/* what forecast_outcomes says of a frame */
enum { OUTCOME_NONE = 0, OUTCOME_FOUND = 1, OUTCOME_UNDECIDED = 2 };

/*
 * forecast_outcomes(ball_times, ball_points, bat_times, knobs, tips, quaternions, windows, t0s,
 *                   out, gravity, drag, degree, horizon, ball_radius, profile, tolerance,
 *                   coarse_step) -> None
 * The predictor's forecasts at many frames of two streams held as arrays (a chunk's plan:
 * contiguous float64, points (m, 3), quaternions (m, 4)): frame k's ball window is samples
 * windows[5k] .. windows[5k + 1] - 1, its bat window windows[5k + 2] .. windows[5k + 3] - 1,
 * the ball's lift from windows[5k + 4] to the ball window's end (int64), its time t0s[k]. Each
 * is what Predictor.predict computes from the same samples: the ball's forecast (ball_forecast,
 * degree 2, from t0, with add_lift), the bat's (bat_window_forecast: step rows
 * from these arrays, the first sample's turn zero) and their first contact within the horizon
 * (first_contact). out[k] (int8): 1 a contact found, 0 none (or a window of fewer than 3
 * samples), 2 undecided (a rank-deficient fit, which the predictor fits again with LAPACK, or
 * forecasts that leave finite numbers, which it reports).
 */
static PyObject *py_forecast_outcomes(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  if (nargs != 17) {
    PyErr_SetString(PyExc_TypeError,
                    "forecast_outcomes(ball_times, ball_points, bat_times, knobs, tips, "
                    "quaternions, windows, t0s, out, gravity, drag, degree, horizon, "
                    "ball_radius, profile, tolerance, coarse_step)");
    return NULL;
  }
  double gravity[3], drag, horizon, rb, tolerance, coarse;
  long degree;
  if (!read_floats(args[9], gravity, 3, "gravity") || !read_number(args[10], &drag) ||
      ((degree = PyLong_AsLong(args[11])) == -1 && PyErr_Occurred()) ||
      !read_number(args[12], &horizon) || !read_number(args[13], &rb) ||
      !read_number(args[15], &tolerance) || !read_number(args[16], &coarse)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "forecast_outcomes: numbers expected");
    }
    return NULL;
  }
  if (degree < 0 || degree > MAX_FIT_DEGREE || !non_negative(rb) || !(tolerance > 0.0) ||
      !(coarse > 0.0) || !isfinite(horizon)) {
    PyErr_SetString(PyExc_ValueError, "forecast_outcomes: 0 <= degree <= 15, ball_radius >= 0, "
                    "tolerance > 0, coarse_step > 0, a finite horizon");
    return NULL;
  }
  if (!load_profile(args[14])) {
    return NULL;
  }
  Py_buffer views[9];
  int held = 0;
  PyObject *result = NULL;
  double *memory = NULL, *steps = NULL;
  Py_ssize_t counts[8];
  for (; held < 8; held++) {
    if (held != 6) {
      if (!get_doubles(args[held], &views[held], &counts[held], "forecast_outcomes", false)) {
        goto done;
      }
      continue;
    }
    if (PyObject_GetBuffer(args[6], &views[6], PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) < 0) {
      goto done;
    }
    counts[6] = views[6].len / 8;
    if (views[6].itemsize != 8 || views[6].format == NULL || strlen(views[6].format) != 1 ||
        strchr("lq", views[6].format[0]) == NULL) {
      held++;
      PyErr_SetString(PyExc_ValueError, "forecast_outcomes: windows must be int64");
      goto done;
    }
  }
  Py_ssize_t frames = counts[7];
  if (!get_items(args[8], &views[8], frames, 1, "bBb?", "forecast_outcomes' out", true)) {
    goto done;
  }
  held = 9;
  Py_ssize_t m_ball = counts[0], m_bat = counts[2];
  if (counts[1] != 3 * m_ball || counts[3] != 3 * m_bat || counts[4] != 3 * m_bat ||
      counts[5] != 4 * m_bat || counts[6] != 5 * frames) {
    PyErr_SetString(PyExc_ValueError, "forecast_outcomes: arrays of mismatched lengths");
    goto done;
  }
  const double *ball_times = views[0].buf, *ball_points = views[1].buf;
  const double *bat_times = views[2].buf, *knobs = views[3].buf, *tips = views[4].buf;
  const double *quaternions = views[5].buf, *t0s = views[7].buf;
  const long long *windows = views[6].buf;
  signed char *out = views[8].buf;
  Py_ssize_t widest = 0, step_from = m_bat, step_end = 0;
  for (Py_ssize_t k = 0; k < frames; k++) {
    const long long *w = windows + 5 * k;
    if (w[0] < 0 || w[1] > m_ball || w[2] < 0 || w[3] > m_bat || w[4] < 0 || w[4] > w[1]) {
      PyErr_SetString(PyExc_IndexError, "forecast_outcomes: a window outside the samples");
      goto done;
    }
    for (int s = 0; s < 2; s++) {
      Py_ssize_t n = (Py_ssize_t)(w[2 * s + 1] - w[2 * s]);
      widest = n > widest ? n : widest;
    }
    widest = w[1] - w[4] > widest ? (Py_ssize_t)(w[1] - w[4]) : widest;
    if (w[3] - w[2] >= 3) {
      step_from = w[2] + 1 < step_from ? (Py_ssize_t)w[2] + 1 : step_from;
      step_end = w[3] > step_end ? (Py_ssize_t)w[3] : step_end;
    }
  }
  /* each bat sample's turn from the one before, once (the windows overlap) */
  if (step_end > step_from) {
    steps = PyMem_Malloc(sizeof(double) * 4 * (size_t)(step_end - step_from));
    if (steps == NULL) {
      PyErr_NoMemory();
      goto done;
    }
    for (Py_ssize_t i = step_from; i < step_end; i++) {
      Vec swing;
      double roll;
      turn_step(v_sub(row3(tips, i - 1), row3(knobs, i - 1)), quaternions + 4 * (i - 1),
                v_sub(row3(tips, i), row3(knobs, i)), quaternions + 4 * i, &swing, &roll);
      double *step = steps + 4 * (i - step_from);
      step[0] = swing.x, step[1] = swing.y, step[2] = swing.z, step[3] = roll;
    }
  }
  memory = widest > 0 ? PyMem_Malloc(sizeof(double) * (size_t)(widest * (1 + BAT_COMPONENTS)))
                      : NULL;
  if (widest > 0 && memory == NULL) {
    PyErr_NoMemory();
    goto done;
  }
  for (Py_ssize_t k = 0; k < frames; k++) {
    const long long *w = windows + 5 * k;
    Py_ssize_t a = (Py_ssize_t)w[0], na = (Py_ssize_t)(w[1] - w[0]);
    Py_ssize_t b = (Py_ssize_t)w[2], nb = (Py_ssize_t)(w[3] - w[2]);
    out[k] = OUTCOME_NONE;
    if (na < 3 || nb < 3) {
      continue;
    }
    double t0 = t0s[k], *x = memory, *y = memory + widest, span, ball[10], bat[21];
    span = ball_array_window(ball_times, ball_points, a, na, t0, x, y);
    int solved = ball_fit_forecast(x, na, 2, y, span, t0, gravity, drag, ball);
    if (solved < 0) {
      goto done;
    }
    if (solved == 0) {
      out[k] = OUTCOME_UNDECIDED;
      continue;
    }
    Py_ssize_t l = (Py_ssize_t)w[4], nl = (Py_ssize_t)(w[1] - w[4]);
    if (nl >= LIFT_MIN_SAMPLES) {
      span = ball_array_window(ball_times, ball_points, l, nl, t0, x, y);
      if (add_lift(x, nl, y, span, gravity, drag, ball) < 0) {
        goto done;
      }
    }
    double t = bat_times[b + nb - 1];
    span = max_of(t - bat_times[b], 1e-9);
    for (Py_ssize_t i = 0; i < nb; i++) {
      double *row = y + BAT_COMPONENTS * i;
      x[i] = (bat_times[b + i] - t) / span;
      memcpy(row, knobs + 3 * (b + i), 3 * sizeof(double));
      memcpy(row + 3, tips + 3 * (b + i), 3 * sizeof(double));
      if (i > 0) {
        memcpy(row + 6, steps + 4 * (b + i - step_from), 4 * sizeof(double));
      }
    }
    cumulate_turns(y, nb);
    solved = bat_fit_forecast(x, nb, (int)degree, y, span, t, bat);
    if (solved < 0) {
      goto done;
    }
    if (solved == 0) {
      out[k] = OUTCOME_UNDECIDED;
      continue;
    }
    BallPath ball_path = {ball[0], {ball[1], ball[2], ball[3]}, {ball[4], ball[5], ball[6]},
                          {ball[7], ball[8], ball[9]}};
    BatPath bat_path;
    memset(&bat_path, 0, sizeof bat_path);
    bat_path.t0 = bat[0];
    bat_path.pivot = (Vec){bat[1], bat[2], bat[3]};
    bat_path.pivot_velocity = (Vec){bat[4], bat[5], bat[6]};
    bat_path.pivot_acceleration = (Vec){bat[7], bat[8], bat[9]};
    bat_path.knob_arm = (Vec){bat[10], bat[11], bat[12]};
    bat_path.tip_arm = (Vec){bat[13], bat[14], bat[15]};
    bat_path.axis = (Vec){bat[16], bat[17], bat[18]};
    bat_path.rate = bat[19];
    bat_path.rate_change = bat[20];
    double t_hit, tau, dt;
    int best;
    Vec piece[6];
    Search found = search_first(&ball_path, &bat_path, t0, horizon, rb, tolerance, coarse,
                                &t_hit, &tau, &dt, &best, piece);
    out[k] = found == SEARCH_FOUND ? OUTCOME_FOUND
                                   : found == SEARCH_BAD ? OUTCOME_UNDECIDED : OUTCOME_NONE;
  }
  result = Py_NewRef(Py_None);
done:
  for (int i = 0; i < held; i++) {
    PyBuffer_Release(&views[i]);
  }
  PyMem_Free(memory);
  PyMem_Free(steps);
  return result;
}

/*
 * point_path_init(path, t0, t1, p0, p1, m0, m1): fill a core.motion.points.PointPath's slots as
 * its Python constructor did, the same operations in its order: t0, t1, a = p0 and end = p1 as
 * given, h = t1 - t0, curved, and for a cubic (m0 and m1 given, m/s) b = h m0, c, d, accel0,
 * accel_rate and bulge (0.25 |c| + 0.38491 |d|), for a chord b = p1 - p0, c = d = 0 and bulge
 * 0; centre (the chord's middle) and radius (half the chord plus the bulge). TypeError: points
 * that are not 3 numbers, times that are not numbers.
 */
static PyObject *path_names[3]; /* "centre", "radius", "bulge" (interned at import) */

static bool set_number(PyObject *o, PyObject *name, double x)
{
  PyObject *value = PyFloat_FromDouble(x);
  int failed = value == NULL || PyObject_SetAttr(o, name, value) < 0;
  Py_XDECREF(value);
  return !failed;
}

static bool set_vec(PyObject *o, PyObject *name, Vec v)
{
  PyObject *value = vec_tuple(v);
  int failed = value == NULL || PyObject_SetAttr(o, name, value) < 0;
  Py_XDECREF(value);
  return !failed;
}

/*
 * The quintic Hermite's power-basis coefficients d, e, f (of s^3, s^4, s^5; s = (t - t0) / h)
 * given the rest: chord = p1 - p0, b = h m0, c = h^2 g0 / 2, slope1 = h m1 and bend1 = h^2 g1
 * (m the end rates, g the end second derivatives): the end value, slope and second derivative
 * at s = 1 are d + e + f = chord - b - c, 3 d + 4 e + 5 f = slope1 - b - 2 c and
 * 6 d + 12 e + 20 f = bend1 - 2 c.
 */
static void quintic_hermite(double chord, double b, double c, double slope1, double bend1,
                            double *d, double *e, double *f)
{
  double value = chord - b - c, slope = slope1 - b - 2.0 * c, bend = bend1 - 2.0 * c;
  *d = 10.0 * value - 4.0 * slope + 0.5 * bend;
  *e = -15.0 * value + 7.0 * slope - bend;
  *f = 6.0 * value - 3.0 * slope + 0.5 * bend;
}

/* the largest |p(s) - chord(s)| over [0, 1] of s^k - s, k = 2 .. 5, rounded up: 1/4, and
 * k^(-k/(k-1)) - k^(-1/(k-1)) in size (0.384900, 0.472470, 0.534992) */
static const double SPAN_BULGE[4] = {0.25, 0.38491, 0.4725, 0.535};

/*
 * point_path_init(path, t0, t1, p0, p1, m0, m1[, g0, g1]): a PointPath's slots
 * (motion.points.PointPath.__init__): a chord (m0, m1 None), the cubic Hermite with end
 * velocities m0, m1, or the quintic Hermite with end accelerations g0, g1 too (m/s^2; None or
 * left out: the cubic). TypeError: times not numbers, points not 3 numbers.
 */
static PyObject *py_point_path_init(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  double t0, t1;
  Vec p0, p1, m0 = {0.0, 0.0, 0.0}, m1 = {0.0, 0.0, 0.0}, g0, g1;
  if ((nargs != 7 && nargs != 9) || !read_number(args[1], &t0) || !read_number(args[2], &t1) ||
      !read_vec(args[3], &p0) || !read_vec(args[4], &p1)) {
    PyErr_SetString(PyExc_TypeError, "point_path_init(path, t0, t1, p0, p1, m0, m1[, g0, g1]): "
                                     "times and points of 3 numbers");
    return NULL;
  }
  bool curved = args[5] != Py_None && args[6] != Py_None;
  if (curved && (!read_vec(args[5], &m0) || !read_vec(args[6], &m1))) {
    PyErr_SetString(PyExc_TypeError, "point_path_init: velocities of 3 numbers");
    return NULL;
  }
  bool quintic = curved && nargs == 9 && args[7] != Py_None && args[8] != Py_None;
  if (quintic && (!read_vec(args[7], &g0) || !read_vec(args[8], &g1))) {
    PyErr_SetString(PyExc_TypeError, "point_path_init: accelerations of 3 numbers");
    return NULL;
  }
  PyObject *path = args[0];
  double h = t1 - t0;
  Vec chord = v_sub(p1, p0);
  if (PyObject_SetAttr(path, piece_names[PIECE_T0], args[1]) < 0 ||
      PyObject_SetAttr(path, piece_names[PIECE_T1], args[2]) < 0 ||
      !set_number(path, piece_names[PIECE_H], h) ||
      PyObject_SetAttr(path, piece_names[PIECE_A], args[3]) < 0 ||
      PyObject_SetAttr(path, piece_names[PIECE_END], args[4]) < 0 ||
      PyObject_SetAttr(path, piece_names[PIECE_CURVED], curved ? Py_True : Py_False) < 0) {
    return NULL;
  }
  double bulge = 0.0;
  if (quintic) {
    double h2 = h * h, b[3], c[3], d[3], e[3], f[3];
    double chords[3] = {chord.x, chord.y, chord.z}, rate0[3] = {m0.x, m0.y, m0.z};
    double rate1[3] = {m1.x, m1.y, m1.z}, bend0[3] = {g0.x, g0.y, g0.z};
    double bend1[3] = {g1.x, g1.y, g1.z};
    for (int i = 0; i < 3; i++) {
      b[i] = h * rate0[i];
      c[i] = 0.5 * h2 * bend0[i];
      quintic_hermite(chords[i], b[i], c[i], h * rate1[i], h2 * bend1[i], &d[i], &e[i], &f[i]);
    }
    Vec vb = {b[0], b[1], b[2]}, vc = {c[0], c[1], c[2]}, vd = {d[0], d[1], d[2]};
    Vec ve = {e[0], e[1], e[2]}, vf = {f[0], f[1], f[2]};
    bulge = SPAN_BULGE[0] * v_norm(vc) + SPAN_BULGE[1] * v_norm(vd) +
            SPAN_BULGE[2] * v_norm(ve) + SPAN_BULGE[3] * v_norm(vf);
    if (!set_vec(path, piece_names[PIECE_B], vb) || !set_vec(path, piece_names[PIECE_C], vc) ||
        !set_vec(path, piece_names[PIECE_D], vd) || !set_vec(path, piece_names[PIECE_E], ve) ||
        !set_vec(path, piece_names[PIECE_F], vf) ||
        !set_vec(path, piece_names[PIECE_ACCEL0], (Vec){g0.x, g0.y, g0.z}) ||
        !set_vec(path, piece_names[PIECE_ACCEL_RATE],
                 (Vec){6.0 * d[0] / h2, 6.0 * d[1] / h2, 6.0 * d[2] / h2})) {
      return NULL;
    }
  } else if (curved) {
    Vec b = {h * m0.x, h * m0.y, h * m0.z}, e = {h * m1.x, h * m1.y, h * m1.z};
    Vec c = {3.0 * chord.x - 2.0 * b.x - e.x, 3.0 * chord.y - 2.0 * b.y - e.y,
             3.0 * chord.z - 2.0 * b.z - e.z};
    Vec d = {b.x + e.x - 2.0 * chord.x, b.y + e.y - 2.0 * chord.y, b.z + e.z - 2.0 * chord.z};
    double h2 = h * h;
    bulge = 0.25 * v_norm(c) + 0.38491 * v_norm(d);
    if (!set_vec(path, piece_names[PIECE_B], b) || !set_vec(path, piece_names[PIECE_C], c) ||
        !set_vec(path, piece_names[PIECE_D], d) ||
        !set_vec(path, piece_names[PIECE_ACCEL0],
                 (Vec){2.0 * c.x / h2, 2.0 * c.y / h2, 2.0 * c.z / h2}) ||
        !set_vec(path, piece_names[PIECE_ACCEL_RATE],
                 (Vec){6.0 * d.x / h2, 6.0 * d.y / h2, 6.0 * d.z / h2})) {
      return NULL;
    }
  } else {
    Vec zero = {0.0, 0.0, 0.0};
    if (!set_vec(path, piece_names[PIECE_B], chord) ||
        !set_vec(path, piece_names[PIECE_C], zero) || !set_vec(path, piece_names[PIECE_D], zero)) {
      return NULL;
    }
  }
  if (!quintic && (PyObject_SetAttr(path, piece_names[PIECE_E], Py_None) < 0 ||
                   PyObject_SetAttr(path, piece_names[PIECE_F], Py_None) < 0)) {
    return NULL;
  }
  if (!set_number(path, path_names[2], bulge) ||
      !set_vec(path, path_names[0], (Vec){p0.x + (p1.x - p0.x) * 0.5, p0.y + (p1.y - p0.y) * 0.5,
                                          p0.z + (p1.z - p0.z) * 0.5}) ||
      !set_number(path, path_names[1], 0.5 * v_norm(chord) + bulge)) {
    return NULL;
  }
  Py_RETURN_NONE;
}

/* width numbers of a row (a sequence) from column on into x; false with an exception */
static bool read_columns(PyObject *row, Py_ssize_t column, Py_ssize_t width, double *x)
{
  PyObject *items = PySequence_Fast(row, "a row must be a sequence");
  if (items == NULL) {
    return false;
  }
  bool ok = PySequence_Fast_GET_SIZE(items) >= column + width;
  for (Py_ssize_t c = 0; ok && c < width; c++) {
    x[c] = item_double(PySequence_Fast_GET_ITEM(items, column + c));
    ok = !PyErr_Occurred();
  }
  Py_DECREF(items);
  if (!ok && !PyErr_Occurred()) {
    PyErr_SetString(PyExc_TypeError, "window_bulge: a row too short");
  }
  return ok;
}

/*
 * window_bulge(times, rows, j, weights, offset, column, width) -> the c2 far test's bulge bound
 * (m) over interval j of a window (core.detector.broadphase.c2: c2_bulge, width 3: points;
 * c2_bat_growth's length, width 1): sum over the samples i of weights[offset + i] times
 * |row_i - chord_j(t_i)| (the columns column .. column + width - 1 of each row; the chord
 * through rows j and j + 1 extended), those of weight 0 left out, added in order from 0.0 (the
 * Python's operations in its order). A weight past the list counts 0 (zip). ValueError: j or
 * offset outside; TypeError: rows that are not numbers.
 */
/* window_bulge's bound on fast sequences (times, rows, weights); false with an exception */
static bool window_bulge_of(PyObject *times, PyObject *rows, PyObject *weights, Py_ssize_t j,
                            Py_ssize_t offset, Py_ssize_t column, Py_ssize_t width,
                            double *out)
{
  Py_ssize_t n = PySequence_Fast_GET_SIZE(times), m = PySequence_Fast_GET_SIZE(weights);
  if (PySequence_Fast_GET_SIZE(rows) < n) {
    n = PySequence_Fast_GET_SIZE(rows);
  }
  if (j < 0 || j + 1 >= n || offset < 0 || column < 0 || (width != 1 && width != 3)) {
    PyErr_SetString(PyExc_ValueError, "window_bulge: an interval or columns outside the window");
    return false;
  }
  double start[3], rate[3], value[3];
  double t0 = item_double(PySequence_Fast_GET_ITEM(times, j));
  double h = item_double(PySequence_Fast_GET_ITEM(times, j + 1)) - t0;
  if (!read_columns(PySequence_Fast_GET_ITEM(rows, j), column, width, start) ||
      !read_columns(PySequence_Fast_GET_ITEM(rows, j + 1), column, width, rate)) {
    return false;
  }
  for (int c = 0; c < width; c++) {
    rate[c] = (rate[c] - start[c]) / h;
  }
  double bound = 0.0;
  for (Py_ssize_t i = 0; i < n && offset + i < m; i++) {
    double weight = item_double(PySequence_Fast_GET_ITEM(weights, offset + i));
    if (PyErr_Occurred()) {
      return false;
    }
    if (weight == 0.0) {
      continue;
    }
    double dt = item_double(PySequence_Fast_GET_ITEM(times, i)) - t0;
    if (PyErr_Occurred() || !read_columns(PySequence_Fast_GET_ITEM(rows, i), column, width,
                                          value)) {
      return false;
    }
    if (width == 1) {
      bound += weight * fabs(value[0] - start[0] - rate[0] * dt);
    } else {
      double dx = value[0] - start[0] - rate[0] * dt, dy = value[1] - start[1] - rate[1] * dt;
      double dz = value[2] - start[2] - rate[2] * dt;
      bound += weight * sqrt(dx * dx + dy * dy + dz * dz);
    }
  }
  *out = bound;
  return !PyErr_Occurred();
}

static PyObject *py_window_bulge(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t j, offset, column, width;
  if (nargs != 7 || !read_index(args[2], &j) || !read_index(args[4], &offset) ||
      !read_index(args[5], &column) || !read_index(args[6], &width)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError,
                      "window_bulge(times, rows, j, weights, offset, column, width)");
    }
    return NULL;
  }
  PyObject *times = PySequence_Fast(args[0], "times must be a sequence");
  PyObject *rows = times ? PySequence_Fast(args[1], "rows must be a sequence") : NULL;
  PyObject *weights = rows ? PySequence_Fast(args[3], "weights must be a sequence") : NULL;
  PyObject *result = NULL;
  double bound;
  if (weights != NULL && window_bulge_of(times, rows, weights, j, offset, column, width,
                                         &bound)) {
    result = PyFloat_FromDouble(bound);
  }
  Py_XDECREF(times);
  Py_XDECREF(rows);
  Py_XDECREF(weights);
  return result;
}

/*
 * bat_growth(times, rows, i, sample0, sample1, weights, far_offset, ratio) -> the bound (m) or
 * None: core.detector.broadphase.c2.c2_bat_growth after its chart (rows: c2_rows' of the
 * window, times their stamps, i the interval; sample0 and sample1 its bat samples), the same
 * operations in the same order: None where the longest step is more than `ratio` times the
 * shortest; else window_bulge of the knob, rotation-vector and length columns (weights from
 * far_offset - i), and B_k + B_L + (L + B_L) (1 - cos(|r_i+1| / 2) + B_r) + |dL| |du| / 4 with
 * du the unit axes' math.dist. ValueError: i outside the rows; TypeError: not rows of 7.
 */
static PyObject *py_bat_growth(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t i, far_offset;
  double ratio;
  if (nargs != 8 || !read_index(args[2], &i) || !read_index(args[6], &far_offset) ||
      !read_number(args[7], &ratio)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "bat_growth(times, rows, i, sample0, sample1, weights, "
                                       "far_offset, ratio)");
    }
    return NULL;
  }
  PyObject *times = PySequence_Fast(args[0], "times must be a sequence");
  PyObject *rows = times ? PySequence_Fast(args[1], "rows must be a sequence") : NULL;
  PyObject *weights = rows ? PySequence_Fast(args[5], "weights must be a sequence") : NULL;
  PyObject *result = NULL, *u0 = NULL, *u1 = NULL;
  if (weights == NULL) {
    goto done;
  }
  Py_ssize_t n = PySequence_Fast_GET_SIZE(times);
  if (n < 2 || PySequence_Fast_GET_SIZE(rows) != n || i < 0 || i + 1 >= n) {
    PyErr_SetString(PyExc_ValueError, "bat_growth: interval i outside the rows");
    goto done;
  }
  /* max and min of the steps, as Python's over the generator (the first of equals) */
  double longest = item_double(PySequence_Fast_GET_ITEM(times, 1)) -
                   item_double(PySequence_Fast_GET_ITEM(times, 0));
  double shortest = longest;
  for (Py_ssize_t m = 2; m < n; m++) {
    double step = item_double(PySequence_Fast_GET_ITEM(times, m)) -
                  item_double(PySequence_Fast_GET_ITEM(times, m - 1));
    longest = step > longest ? step : longest;
    shortest = step < shortest ? step : shortest;
  }
  if (PyErr_Occurred()) {
    goto done;
  }
  if (longest > ratio * shortest) {
    result = Py_NewRef(Py_None);
    goto done;
  }
  double knob, turn, stretch, closing[3], lengths[2];
  if (!window_bulge_of(times, rows, weights, i, far_offset - i, 0, 3, &knob) ||
      !window_bulge_of(times, rows, weights, i, far_offset - i, 3, 3, &turn) ||
      !window_bulge_of(times, rows, weights, i, far_offset - i, 6, 1, &stretch) ||
      !read_columns(PySequence_Fast_GET_ITEM(rows, i + 1), 3, 3, closing) ||
      !read_columns(PySequence_Fast_GET_ITEM(rows, i), 6, 1, &lengths[0]) ||
      !read_columns(PySequence_Fast_GET_ITEM(rows, i + 1), 6, 1, &lengths[1])) {
    goto done;
  }
  double half_cos = cos(0.5 * sqrt(closing[0] * closing[0] + closing[1] * closing[1] +
                                   closing[2] * closing[2]));
  double longer = lengths[1] > lengths[0] ? lengths[1] : lengths[0];
  Vec knob0, knob1, axis0, axis1;
  double length0, length1;
  if (!bat_axis(args[3], &knob0, &axis0, &length0) ||
      !bat_axis(args[4], &knob1, &axis1, &length1) || (u0 = vec_tuple(axis0)) == NULL ||
      (u1 = vec_tuple(axis1)) == NULL) {
    goto done;
  }
  double du = python_dist(u0, u1);
  if (!PyErr_Occurred()) {
    result = PyFloat_FromDouble((knob + stretch + (longer + stretch) * (1.0 - half_cos + turn)) +
                                0.25 * fabs(lengths[1] - lengths[0]) * du);
  }
done:
  Py_XDECREF(times);
  Py_XDECREF(rows);
  Py_XDECREF(weights);
  Py_XDECREF(u0);
  Py_XDECREF(u1);
  return result;
}

/*
 * recharted(reference, origin, turn, rate, step) -> (rotation vector, its rate): a rotation
 * vector and its rate (rad, rad/s) moved from the chart about unit ``reference`` to the one
 * about unit ``origin`` (core.detector.fitting._recharted): the direction reference turned by
 * ``turn``, charted from origin; the rate by central differences, turn +- (step / |rate|)
 * rate (step in rad); (0, 0, 0) where the rate is zero.
 */
static PyObject *py_recharted(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Vec reference, origin, turn, rate;
  double step;
  if (nargs != 5 || !read_vec(args[0], &reference) || !read_vec(args[1], &origin) ||
      !read_vec(args[2], &turn) || !read_vec(args[3], &rate) || !read_number(args[4], &step)) {
    PyErr_SetString(PyExc_TypeError,
                    "recharted(reference, origin, turn, rate, step): four 3-vectors, a number");
    return NULL;
  }
  bool same;
  Vec at = rotation_to(origin, rotate_by(reference, turn, &same));
  double speed = sqrt(rate.x * rate.x + rate.y * rate.y + rate.z * rate.z);
  Vec change = {0.0, 0.0, 0.0};
  if (speed != 0.0) {
    double h = step / speed; /* s */
    Vec forward = {turn.x + h * rate.x, turn.y + h * rate.y, turn.z + h * rate.z};
    Vec ahead = rotation_to(origin, rotate_by(reference, forward, &same));
    Vec behind = rotation_to(origin, rotate_by(reference, v_sub(turn, v_scale(rate, h)), &same));
    change = (Vec){(ahead.x - behind.x) / (2.0 * h), (ahead.y - behind.y) / (2.0 * h),
                   (ahead.z - behind.z) / (2.0 * h)};
  }
  return Py_BuildValue("(NN)", vec_tuple(at), vec_tuple(change));
}

/* bat_axis(sample) -> (unit knob-to-tip direction, length in m) */
static PyObject *py_bat_axis(PyObject *self, PyObject *sample)
{
  Vec knob, direction;
  double length;
  if (!bat_axis(sample, &knob, &direction, &length)) {
    return NULL;
  }
  return Py_BuildValue("(N d)", vec_tuple(direction), length);
}

/* rotation_to(reference, direction) -> the rotation vector (rad) turning one onto the other */
static PyObject *py_rotation_to(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Vec reference, direction;
  if (nargs != 2 || !read_vec(args[0], &reference) || !read_vec(args[1], &direction)) {
    PyErr_SetString(PyExc_TypeError, "rotation_to(reference, direction): two 3-vectors");
    return NULL;
  }
  return vec_tuple(rotation_to(reference, direction));
}

/*
 * c2_chart(samples, j, max_angle) -> (first, rows): the c2 window's rows for the interval from
 * samples[j] to samples[j + 1] (core.motion.c2.c2_rows): per sample from ``first`` on, its
 * knob (m), the rotation vector (rad) from samples[j]'s direction onto its own, its length
 * (m). A sample before j turned more than max_angle (rad) from it starts the window after
 * it; one after j + 1 ends the window before it.
 */
static PyObject *py_c2_chart(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t j;
  double max_angle;
  if (nargs != 3 ||
      !read_index(args[1], &j) ||
      !read_number(args[2], &max_angle)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "c2_chart(samples, j, max_angle)");
    }
    return NULL;
  }
  PyObject *samples = PySequence_Fast(args[0], "samples must be a sequence");
  if (samples == NULL) {
    return NULL;
  }
  PyObject *result = NULL;
  Py_ssize_t n = PySequence_Fast_GET_SIZE(samples);
  double *rows = NULL;
  if (j < 0 || j >= n) {
    PyErr_SetString(PyExc_IndexError, "c2_chart: j outside the samples");
    goto done;
  }
  rows = PyMem_Malloc(sizeof(double) * (size_t)(7 * n));
  if (rows == NULL) {
    PyErr_NoMemory();
    goto done;
  }
  Vec knob, reference, direction;
  double length;
  if (!bat_axis(PySequence_Fast_GET_ITEM(samples, j), &knob, &reference, &length)) {
    goto done;
  }
  Py_ssize_t first = 0, count = 0;
  for (Py_ssize_t i = 0; i < n; i++) {
    if (!bat_axis(PySequence_Fast_GET_ITEM(samples, i), &knob, &direction, &length)) {
      goto done;
    }
    Vec r = rotation_to(reference, direction);
    if (sqrt(r.x * r.x + r.y * r.y + r.z * r.z) > max_angle) {
      if (i < j) {
        first = i + 1;
        count = 0;
        continue;
      }
      if (i > j + 1) {
        break;
      }
    }
    double *row = rows + 7 * count++;
    row[0] = knob.x, row[1] = knob.y, row[2] = knob.z;
    row[3] = r.x, row[4] = r.y, row[5] = r.z, row[6] = length;
  }
  PyObject *list = float_rows(rows, count, 7, true);
  if (list != NULL) {
    result = Py_BuildValue("(nN)", first, list);
  }
done:
  PyMem_Free(rows);
  Py_DECREF(samples);
  return result;
}

/* a float attribute of a path piece; false with an exception */
static bool attr_double(PyObject *o, PyObject *name, double *x)
{
  PyObject *value = PyObject_GetAttr(o, name);
  if (value == NULL) {
    return false;
  }
  *x = PyFloat_AsDouble(value);
  Py_DECREF(value);
  return !(*x == -1.0 && PyErr_Occurred());
}

/* a 3-vector attribute of a path piece; false with an exception */
static bool attr_vec(PyObject *o, PyObject *name, Vec *v)
{
  PyObject *value = PyObject_GetAttr(o, name);
  if (value == NULL) {
    return false;
  }
  bool ok = read_vec(value, v);
  Py_DECREF(value);
  if (!ok) {
    PyErr_Format(PyExc_TypeError, "a path piece's %U must be 3 numbers", name);
  }
  return ok;
}

/* a piece's ``curved`` flag: 1, 0, or -1 with an exception */
static int attr_curved(PyObject *o)
{
  PyObject *value = PyObject_GetAttr(o, piece_names[PIECE_CURVED]);
  if (value == NULL) {
    return -1;
  }
  int curved = PyObject_IsTrue(value);
  Py_DECREF(value);
  return curved;
}

/* whether a path piece is a quintic (its ``e`` is not None): 1, 0, or -1 with an exception */
static int piece_quintic(PyObject *piece)
{
  PyObject *value = PyObject_GetAttr(piece, piece_names[PIECE_E]);
  if (value == NULL) {
    return -1;
  }
  int quintic = value != Py_None;
  Py_DECREF(value);
  return quintic;
}

/*
 * A bound on the largest |p''| over [sa, sb] (in steps; times h^2) of a quintic with power
 * coefficients c, d, e, f of s^2 .. s^5 (`dim` coordinates each): p'' h^2 = 2 c + 6 d s +
 * 12 e s^2 + 20 f s^3, bounded by Taylor's theorem about sa: |p''(sa)| + |p'''(sa)| (sb - sa)
 * + max |p''''| (sb - sa)^2 / 2, where p'''' h^4 = 24 e + 120 f s is linear (so at an end).
 */
static double quintic_bend_bound(const double *c, const double *d, const double *e,
                                 const double *f, int dim, double sa, double sb)
{
  double bend = 0.0, jerk = 0.0, snap_a = 0.0, snap_b = 0.0, span = sb - sa;
  for (int i = 0; i < dim; i++) {
    double second = 2.0 * c[i] + sa * (6.0 * d[i] + sa * (12.0 * e[i] + sa * 20.0 * f[i]));
    double third = 6.0 * d[i] + sa * (24.0 * e[i] + sa * 60.0 * f[i]);
    double fourth_a = 24.0 * e[i] + 120.0 * f[i] * sa, fourth_b = 24.0 * e[i] + 120.0 * f[i] * sb;
    bend += second * second;
    jerk += third * third;
    snap_a += fourth_a * fourth_a;
    snap_b += fourth_b * fourth_b;
  }
  return sqrt(bend) + sqrt(jerk) * span + max_of(sqrt(snap_a), sqrt(snap_b)) * span * span * 0.5;
}

/*
 * The largest |p''| over [ta, tb] of a point piece (motion.points.PointPath): p''(s) =
 * accel0 + accel_rate s, s = (t - t0) / h, linear, so at an end; 0 for a chord; of a quintic,
 * quintic_bend_bound over h^2. -1 with an exception.
 */
static double piece_max_acceleration(PyObject *piece, double ta, double tb)
{
  int curved = attr_curved(piece);
  double t0, h;
  Vec a0, rate;
  if (curved <= 0) {
    return curved == 0 ? 0.0 : -1.0;
  }
  int quintic = piece_quintic(piece);
  if (quintic != 0) {
    Vec c, d, e, f;
    if (quintic < 0 || !attr_double(piece, piece_names[PIECE_T0], &t0) ||
        !attr_double(piece, piece_names[PIECE_H], &h) ||
        !attr_vec(piece, piece_names[PIECE_C], &c) || !attr_vec(piece, piece_names[PIECE_D], &d) ||
        !attr_vec(piece, piece_names[PIECE_E], &e) || !attr_vec(piece, piece_names[PIECE_F], &f)) {
      return -1.0;
    }
    double cs[3] = {c.x, c.y, c.z}, ds[3] = {d.x, d.y, d.z}, es[3] = {e.x, e.y, e.z};
    double fs[3] = {f.x, f.y, f.z};
    return quintic_bend_bound(cs, ds, es, fs, 3, (ta - t0) / h, (tb - t0) / h) / (h * h);
  }
  if (!attr_double(piece, piece_names[PIECE_T0], &t0) ||
      !attr_double(piece, piece_names[PIECE_H], &h) ||
      !attr_vec(piece, piece_names[PIECE_ACCEL0], &a0) ||
      !attr_vec(piece, piece_names[PIECE_ACCEL_RATE], &rate)) {
    return -1.0;
  }
  double worst = 0.0;
  double ends[2] = {ta, tb};
  for (int i = 0; i < 2; i++) {
    double s = (ends[i] - t0) / h;
    Vec p = {a0.x + rate.x * s, a0.y + rate.y * s, a0.z + rate.z * s};
    worst = max_of(worst, sqrt(p.x * p.x + p.y * p.y + p.z * p.z));
  }
  return worst;
}

/* a c2 bat path's pieces (motion.c2.C2BatPath: "turn", "length", "reference"; interned) */
static PyObject *c2_path_names[3];
static PyObject *parabolas_name; /* "parabolas": a stream's kept parabolas (kept_parabola) */

/*
 * A point piece's position at t (motion.points.PointPath.at): the stored end object at t0 or
 * t1, else a + s (b + s (c + s d)), s = (t - t0) / h, per coordinate; into *value, and as a new
 * reference (the end object itself, or a new tuple) when `object` is not NULL. False with an
 * exception.
 */
static bool point_piece_at(PyObject *piece, double t, Vec *value, PyObject **object)
{
  double t0, t1, h;
  if (!attr_double(piece, piece_names[PIECE_T0], &t0) ||
      !attr_double(piece, piece_names[PIECE_T1], &t1)) {
    return false;
  }
  if (t == t0 || t == t1) {
    PyObject *end = PyObject_GetAttr(piece, piece_names[t == t0 ? PIECE_A : PIECE_END]);
    if (end == NULL || !read_vec(end, value)) {
      if (end != NULL) {
        PyErr_SetString(PyExc_TypeError, "a path piece's ends must be 3 numbers");
      }
      Py_XDECREF(end);
      return false;
    }
    if (object != NULL) {
      *object = end;
    } else {
      Py_DECREF(end);
    }
    return true;
  }
  Vec a, b, c, d, e, f;
  int quintic = piece_quintic(piece);
  if (quintic < 0 || !attr_double(piece, piece_names[PIECE_H], &h) ||
      !attr_vec(piece, piece_names[PIECE_A], &a) || !attr_vec(piece, piece_names[PIECE_B], &b) ||
      !attr_vec(piece, piece_names[PIECE_C], &c) || !attr_vec(piece, piece_names[PIECE_D], &d) ||
      (quintic && (!attr_vec(piece, piece_names[PIECE_E], &e) ||
                   !attr_vec(piece, piece_names[PIECE_F], &f)))) {
    return false;
  }
  double s = (t - t0) / h;
  if (quintic) {
    *value = (Vec){a.x + s * (b.x + s * (c.x + s * (d.x + s * (e.x + s * f.x)))),
                   a.y + s * (b.y + s * (c.y + s * (d.y + s * (e.y + s * f.y)))),
                   a.z + s * (b.z + s * (c.z + s * (d.z + s * (e.z + s * f.z))))};
  } else {
    *value = (Vec){a.x + s * (b.x + s * (c.x + s * d.x)), a.y + s * (b.y + s * (c.y + s * d.y)),
                   a.z + s * (b.z + s * (c.z + s * d.z))};
  }
  if (object != NULL && (*object = vec_tuple(*value)) == NULL) {
    return false;
  }
  return true;
}

/* an angle piece's value at t (motion.points.AngleCubic.at); false with an exception */
static bool angle_piece_at(PyObject *piece, double t, double *value)
{
  double t0, t1, h, a, b, c, d;
  if (!attr_double(piece, piece_names[PIECE_T0], &t0) ||
      !attr_double(piece, piece_names[PIECE_T1], &t1)) {
    return false;
  }
  if (t == t0 || t == t1) {
    return attr_double(piece, piece_names[t == t0 ? PIECE_A : PIECE_END], value);
  }
  int quintic = piece_quintic(piece);
  double e, f;
  if (quintic < 0 || !attr_double(piece, piece_names[PIECE_H], &h) ||
      !attr_double(piece, piece_names[PIECE_A], &a) ||
      !attr_double(piece, piece_names[PIECE_B], &b) ||
      !attr_double(piece, piece_names[PIECE_C], &c) ||
      !attr_double(piece, piece_names[PIECE_D], &d) ||
      (quintic && (!attr_double(piece, piece_names[PIECE_E], &e) ||
                   !attr_double(piece, piece_names[PIECE_F], &f)))) {
    return false;
  }
  double s = (t - t0) / h;
  *value = quintic ? a + s * (b + s * (c + s * (d + s * (e + s * f))))
                   : a + s * (b + s * (c + s * d));
  return true;
}

/*
 * A c2 bat path's knob and tip at t inside its interval (c2_inside's numbers): *knob_object a
 * new reference to the knob as c2_inside returns it when knob_object is not NULL (the caller
 * releases it, also on failure). False with an exception.
 */
static bool c2_inside_at(PyObject *path, double t, Vec *knob, Vec *tip, PyObject **knob_object)
{
  PyObject *knob_piece = PyObject_GetAttr(path, knob_name);
  PyObject *turn_piece = knob_piece ? PyObject_GetAttr(path, c2_path_names[0]) : NULL;
  PyObject *length_piece = turn_piece ? PyObject_GetAttr(path, c2_path_names[1]) : NULL;
  Vec reference, turn_at;
  double length;
  bool ok = length_piece != NULL && attr_vec(path, c2_path_names[2], &reference) &&
            point_piece_at(knob_piece, t, knob, knob_object) &&
            point_piece_at(turn_piece, t, &turn_at, NULL) &&
            angle_piece_at(length_piece, t, &length);
  if (ok) {
    bool same;
    Vec d = rotate_by(reference, turn_at, &same);
    *tip = (Vec){knob->x + length * d.x, knob->y + length * d.y, knob->z + length * d.z};
  }
  Py_XDECREF(knob_piece);
  Py_XDECREF(turn_piece);
  Py_XDECREF(length_piece);
  return ok;
}

/*
 * c2_inside(path, t) -> (knob, tip): a c2 bat path at t (motion.c2.C2BatPath._inside, the same
 * operations in the same order): its knob piece at t, its reference direction turned by the
 * turn piece at t (rotate), the tip the knob plus the length piece at t times it.
 * AttributeError / TypeError: not such a path.
 */
static PyObject *py_c2_inside(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  double t;
  if (nargs != 2 || !read_number(args[1], &t)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "c2_inside(path, t)");
    }
    return NULL;
  }
  PyObject *knob = NULL, *tip = NULL, *result = NULL;
  Vec knob_at, tip_at;
  if (c2_inside_at(args[0], t, &knob_at, &tip_at, &knob) && (tip = vec_tuple(tip_at)) != NULL) {
    result = PyTuple_Pack(2, knob, tip);
  }
  Py_XDECREF(tip);
  Py_XDECREF(knob);
  return result;
}

/*
 * c2_deviation(knob, turn, length, ta, tb) -> a bound (m) on how far any axis point of a c2
 * bat (motion.c2.C2BatPath: its knob and rotation vector point pieces, its length an angle
 * piece) leaves its chord over [ta, tb] (s): max |p''| (tb - ta)^2 / 8 with
 * |p''| <= |knob''| + |L''| + 2 |L'| |u'| + L |u''|, |u'| <= |r'|, |u''| <= |r''| + 2 |r'|^2
 * (C2BatPath._deviation), each bound from the pieces' stored power-basis coefficients.
 */
static PyObject *py_c2_deviation(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  double ta, tb;
  if (nargs != 5 || !read_number(args[3], &ta) || !read_number(args[4], &tb)) {
    PyErr_SetString(PyExc_TypeError, "c2_deviation(knob, turn, length, ta, tb)");
    return NULL;
  }
  PyObject *turn = args[1], *length = args[2];
  double span = tb - ta;
  /* the rotation vector: |r''| at most ``second``, |r'| at most ``first`` */
  double second = piece_max_acceleration(turn, ta, tb);
  double t0, h, t1, a, end, b, c, d, e = 0.0, f = 0.0, accel0, accel_rate;
  Vec vb, vc, vd, ve = {0.0, 0.0, 0.0}, vf = {0.0, 0.0, 0.0};
  int quintic = second < 0.0 ? -1 : piece_quintic(turn);
  if (quintic < 0 || !attr_double(turn, piece_names[PIECE_T0], &t0) ||
      !attr_double(turn, piece_names[PIECE_H], &h) ||
      !attr_vec(turn, piece_names[PIECE_B], &vb) || !attr_vec(turn, piece_names[PIECE_C], &vc) ||
      !attr_vec(turn, piece_names[PIECE_D], &vd) ||
      (quintic && (!attr_vec(turn, piece_names[PIECE_E], &ve) ||
                   !attr_vec(turn, piece_names[PIECE_F], &vf)))) {
    return NULL;
  }
  double s = (ta - t0) / h;
  Vec rate = quintic ? (Vec){
      (vb.x + s * (2.0 * vc.x + s * (3.0 * vd.x + s * (4.0 * ve.x + 5.0 * s * vf.x)))) / h,
      (vb.y + s * (2.0 * vc.y + s * (3.0 * vd.y + s * (4.0 * ve.y + 5.0 * s * vf.y)))) / h,
      (vb.z + s * (2.0 * vc.z + s * (3.0 * vd.z + s * (4.0 * ve.z + 5.0 * s * vf.z)))) / h}
                     : (Vec){(vb.x + s * (2.0 * vc.x + 3.0 * s * vd.x)) / h,
                             (vb.y + s * (2.0 * vc.y + 3.0 * s * vd.y)) / h,
                             (vb.z + s * (2.0 * vc.z + 3.0 * s * vd.z)) / h};
  double first = sqrt(rate.x * rate.x + rate.y * rate.y + rate.z * rate.z) + second * span;
  /* the length: |L| at most ``value``, |L'| at most ``lengthening``, |L''| at most ``change`` */
  int curved = attr_curved(length);
  quintic = curved < 0 ? -1 : piece_quintic(length);
  if (quintic < 0 || !attr_double(length, piece_names[PIECE_T0], &t0) ||
      !attr_double(length, piece_names[PIECE_T1], &t1) ||
      !attr_double(length, piece_names[PIECE_H], &h) ||
      !attr_double(length, piece_names[PIECE_A], &a) ||
      !attr_double(length, piece_names[PIECE_END], &end) ||
      !attr_double(length, piece_names[PIECE_B], &b) ||
      !attr_double(length, piece_names[PIECE_C], &c) ||
      !attr_double(length, piece_names[PIECE_D], &d) ||
      (quintic && (!attr_double(length, piece_names[PIECE_E], &e) ||
                   !attr_double(length, piece_names[PIECE_F], &f)))) {
    return NULL;
  }
  double change = 0.0;
  if (quintic) {
    change = quintic_bend_bound(&c, &d, &e, &f, 1, (ta - t0) / h, (tb - t0) / h) / (h * h);
  } else if (curved) {
    if (!attr_double(length, piece_names[PIECE_ACCEL0], &accel0) ||
        !attr_double(length, piece_names[PIECE_ACCEL_RATE], &accel_rate)) {
      return NULL;
    }
    change = max_of(fabs(accel0 + accel_rate * (ta - t0) / h),
                    fabs(accel0 + accel_rate * (tb - t0) / h));
  }
  s = (ta - t0) / h;
  double lengthening =
      fabs(quintic ? (b + s * (2.0 * c + s * (3.0 * d + s * (4.0 * e + 5.0 * s * f)))) / h
                   : (b + s * (2.0 * c + 3.0 * s * d)) / h) + change * span;
  double at[2], ends[2] = {ta, tb};
  for (int i = 0; i < 2; i++) { /* AngleCubic.at: its ends as given */
    double u = (ends[i] - t0) / h;
    at[i] = ends[i] == t0 ? a : ends[i] == t1 ? end
          : quintic ? a + u * (b + u * (c + u * (d + u * (e + u * f))))
                    : a + u * (b + u * (c + u * d));
  }
  double value = max_of(fabs(at[0]), fabs(at[1])) + change * span * span / 8.0;
  double knob = piece_max_acceleration(args[0], ta, tb);
  if (knob < 0.0) {
    return NULL;
  }
  double bend = second + 2.0 * first * first;
  return PyFloat_FromDouble((knob + change + 2.0 * lengthening * first + value * bend) * span *
                            span / 8.0);
}

/* a c2 bat path's own attributes c2_path_init sets (interned at import) */
enum { C2_SAMPLE0, C2_SAMPLE1, C2_ANGLE, C2_LEVER, C2_SPREAD, C2_OWN_NAMES };
static const char *const c2_own_attributes[C2_OWN_NAMES] = {"sample0", "sample1", "angle",
                                                            "lever", "spread"};
static PyObject *c2_own_names[C2_OWN_NAMES];

/* a c2 bat path's knob and tip at t (motion.bat_paths.BatPath.at: its samples' at its ends, else
 * c2_inside_at); false with an exception */
static bool c2_ends_at(PyObject *path, double t, Vec *knob, Vec *tip)
{
  double t0, t1;
  if (!attr_double(path, piece_names[PIECE_T0], &t0) ||
      !attr_double(path, piece_names[PIECE_T1], &t1)) {
    return false;
  }
  if (t != t0 && t != t1) {
    return c2_inside_at(path, t, knob, tip, NULL);
  }
  PyObject *sample = PyObject_GetAttr(path, c2_own_names[t == t0 ? C2_SAMPLE0 : C2_SAMPLE1]);
  PyObject *knob_object = NULL, *tip_object = NULL;
  bool ok = sample != NULL && bat_ends(sample, knob, tip, &knob_object, &tip_object);
  Py_XDECREF(knob_object);
  Py_XDECREF(tip_object);
  Py_XDECREF(sample);
  return ok;
}

/*
 * zone_clear(ball_path, bat_path, ta, tb, n, ball_radius, profile, floor) -> whether a ball on a
 * point path (motion.points.PointPath) stays farther than floor (m) from a c2 bat
 * (motion.c2.C2BatPath) over [ta, tb] (s), by the bound of core.detector.sweep.Sweep.
 * _outside_zone (the same operations in the same order): at the n + 1 instants ta + (tb - ta) j /
 * n (tb the last) the gap (profile_gap) beyond floor, and between each two the mean of their
 * gaps less half of how far the ball and the farther bat end moved (each the square root of the
 * summed squares) beyond it. False as soon as one is not. TypeError / AttributeError: not such
 * paths or numbers.
 */
static PyObject *py_zone_clear(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  double ta, tb, ball_radius, floor;
  long n;
  if (nargs != 8 || !read_number(args[2], &ta) || !read_number(args[3], &tb) ||
      (n = PyLong_AsLong(args[4])) < 1 || !read_number(args[5], &ball_radius) ||
      !read_number(args[7], &floor)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "zone_clear(ball_path, bat_path, ta, tb, n >= 1, "
                                       "ball_radius, profile, floor)");
    }
    return NULL;
  }
  if (!load_profile(args[6])) {
    return NULL;
  }
  Vec ball, knob, tip, before_ball = {0.0, 0.0, 0.0}, before_knob = before_ball;
  Vec before_tip = before_ball;
  double before_gap = 0.0, fraction;
  for (long j = 0; j <= n; j++) {
    double t = j == n ? tb : ta + (tb - ta) * (double)j / (double)n;
    if (!point_piece_at(args[0], t, &ball, NULL) || !c2_ends_at(args[1], t, &knob, &tip)) {
      return NULL;
    }
    double gap = profile_gap_at(ball, knob, tip, ball_radius, &fraction, NULL, NULL);
    if (!(gap > floor)) {
      Py_RETURN_FALSE;
    }
    if (j > 0) {
      double moved = v_norm(v_sub(ball, before_ball)) +
                     max_of(v_norm(v_sub(knob, before_knob)), v_norm(v_sub(tip, before_tip)));
      if (!(0.5 * (gap + before_gap - moved) > floor)) {
        Py_RETURN_FALSE;
      }
    }
    before_ball = ball, before_knob = knob, before_tip = tip, before_gap = gap;
  }
  Py_RETURN_TRUE;
}

/* a new instance of a Python class with __slots__, its __init__ not called; NULL with an error */
static PyObject *bare_instance(PyObject *cls)
{
  if (!PyType_Check(cls)) {
    PyErr_SetString(PyExc_TypeError, "c2_path_init: PointPath and AngleCubic must be classes");
    return NULL;
  }
  PyTypeObject *type = (PyTypeObject *)cls;
  PyObject *nothing = PyTuple_New(0);
  PyObject *made = nothing ? type->tp_new(type, nothing, NULL) : NULL;
  Py_XDECREF(nothing);
  return made;
}

/*
 * An AngleCubic's slots (motion.points.AngleCubic.__init__, its operations in its order): t0,
 * t1 as given, h = t1 - t0, a = v0, end = v1, curved (both rates given), e = f = None, and b,
 * c, d, accel0, accel_rate, bulge for a cubic (b = h m0, with h m1 as m: c = 3 chord - 2 b - m,
 * d = b + m - 2 chord, 2 c / h^2, 6 d / h^2, 0.25 |c| + 0.38491 |d|), else b = the chord,
 * c = d = 0 and bulge 0; with the rates' rates g0, g1 too, the quintic (quintic_hermite:
 * b = h m0, c = h^2 g0 / 2, d, e, f; accel0 = g0, accel_rate = 6 d / h^2, the bulge by
 * SPAN_BULGE). False with an exception.
 */
static bool fill_angle_cubic(PyObject *piece, PyObject *t0_object, PyObject *t1_object,
                             double t0, double t1, double v0, double v1, PyObject *m0_object,
                             PyObject *m1_object, PyObject *g0_object, PyObject *g1_object)
{
  double h = t1 - t0, chord = v1 - v0, m0 = 0.0, m1 = 0.0, g0 = 0.0, g1 = 0.0;
  bool curved = m0_object != Py_None && m1_object != Py_None;
  if (curved && (!read_number(m0_object, &m0) || !read_number(m1_object, &m1))) {
    PyErr_SetString(PyExc_TypeError, "c2_path_init: length rates must be numbers or None");
    return false;
  }
  bool quintic = curved && g0_object != Py_None && g1_object != Py_None;
  if (quintic && (!read_number(g0_object, &g0) || !read_number(g1_object, &g1))) {
    PyErr_SetString(PyExc_TypeError, "c2_path_init: length accelerations must be numbers");
    return false;
  }
  if (PyObject_SetAttr(piece, piece_names[PIECE_T0], t0_object) < 0 ||
      PyObject_SetAttr(piece, piece_names[PIECE_T1], t1_object) < 0 ||
      !set_number(piece, piece_names[PIECE_H], h) || !set_number(piece, piece_names[PIECE_A], v0) ||
      !set_number(piece, piece_names[PIECE_END], v1) ||
      PyObject_SetAttr(piece, piece_names[PIECE_CURVED], curved ? Py_True : Py_False) < 0) {
    return false;
  }
  if (!quintic && (PyObject_SetAttr(piece, piece_names[PIECE_E], Py_None) < 0 ||
                   PyObject_SetAttr(piece, piece_names[PIECE_F], Py_None) < 0)) {
    return false;
  }
  if (!curved) {
    return set_number(piece, piece_names[PIECE_B], chord) &&
           set_number(piece, piece_names[PIECE_C], 0.0) &&
           set_number(piece, piece_names[PIECE_D], 0.0) &&
           set_number(piece, path_names[2], 0.0);
  }
  if (quintic) {
    double h2 = h * h, b = h * m0, c = 0.5 * h2 * g0, d, e, f;
    quintic_hermite(chord, b, c, h * m1, h2 * g1, &d, &e, &f);
    return set_number(piece, piece_names[PIECE_B], b) &&
           set_number(piece, piece_names[PIECE_C], c) &&
           set_number(piece, piece_names[PIECE_D], d) &&
           set_number(piece, piece_names[PIECE_E], e) &&
           set_number(piece, piece_names[PIECE_F], f) &&
           set_number(piece, piece_names[PIECE_ACCEL0], g0) &&
           set_number(piece, piece_names[PIECE_ACCEL_RATE], 6.0 * d / h2) &&
           set_number(piece, path_names[2], SPAN_BULGE[0] * fabs(c) + SPAN_BULGE[1] * fabs(d) +
                                                SPAN_BULGE[2] * fabs(e) + SPAN_BULGE[3] * fabs(f));
  }
  double b = h * m0, e = h * m1;
  double c = 3.0 * chord - 2.0 * b - e, d = b + e - 2.0 * chord, h2 = h * h;
  return set_number(piece, piece_names[PIECE_B], b) && set_number(piece, piece_names[PIECE_C], c) &&
         set_number(piece, piece_names[PIECE_D], d) &&
         set_number(piece, piece_names[PIECE_ACCEL0], 2.0 * c / h2) &&
         set_number(piece, piece_names[PIECE_ACCEL_RATE], 6.0 * d / h2) &&
         set_number(piece, path_names[2], 0.25 * fabs(c) + 0.38491 * fabs(d));
}

/* item i (0 or 1) of a pair of slopes (a sequence of two), a new reference; NULL with an error */
static PyObject *slope_item(PyObject *pair, Py_ssize_t i)
{
  if (!PySequence_Check(pair) || PySequence_Size(pair) != 2) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "c2_path_init: slopes must be pairs (start, end)");
    }
    return NULL;
  }
  return PySequence_GetItem(pair, i);
}

/*
 * c2_path_init(path, point_class, angle_class, t0, t1, sample0, sample1, knob_slopes,
 * turn_slopes, length_slopes): fill a motion.c2.C2BatPath's slots as its Python constructor
 * did, the same operations in its order: the BatPath part (t0, t1 as given, h, the samples,
 * centre the mean of the four ends, radius the largest math.dist from it); the knob a PointPath
 * (point_class, through point_path_init) from the samples' knobs with knob_slopes; the
 * reference and the lengths the samples' bat_axis; the turn a PointPath from (0, 0, 0) to the
 * rotation vector turning the reference onto sample1's direction, with turn_slopes; the length
 * an AngleCubic (angle_class) with length_slopes; lever the longer length, angle the turn's
 * norm, spread the path's c2_deviation over [t0, t1], radius grown by it. Slopes: pairs of
 * start and end rates (None for none). TypeError: arguments not of those kinds.
 */
static PyObject *py_c2_path_init(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  double t0, t1;
  if ((nargs != 10 && nargs != 11) || !read_number(args[3], &t0) || !read_number(args[4], &t1)) {
    PyErr_SetString(PyExc_TypeError, "c2_path_init(path, point_class, angle_class, t0, t1, "
                                     "sample0, sample1, knob_slopes, turn_slopes, "
                                     "length_slopes[, seconds]): times must be numbers");
    return NULL;
  }
  /* seconds: None, or (knob, turn, length) second derivatives, each a (start, end) pair */
  PyObject *bends = nargs == 11 && args[10] != Py_None ? args[10] : NULL;
  PyObject *path = args[0], *t0_object = args[3], *t1_object = args[4];
  PyObject *sample0 = args[5], *sample1 = args[6];
  PyObject *ends[4] = {NULL, NULL, NULL, NULL}; /* knob0, tip0, knob1, tip1 */
  PyObject *centre = NULL, *knob = NULL, *turn = NULL, *length = NULL, *origin = NULL;
  PyObject *closing = NULL, *reference = NULL, *spread = NULL, *slopes[6] = {NULL};
  PyObject *seconds[6] = {NULL};
  PyObject *result = NULL;
  Vec k0, e0, k1, e1, axis0, axis1;
  double length0, length1;
  if (!bat_ends(sample0, &k0, &e0, &ends[0], &ends[1]) ||
      !bat_ends(sample1, &k1, &e1, &ends[2], &ends[3]) ||
      !ends_axis(k0, e0, ends[0], ends[1], &axis0, &length0) ||
      !ends_axis(k1, e1, ends[2], ends[3], &axis1, &length1)) {
    goto done;
  }
  for (int i = 0; i < 6; i++) {
    if ((slopes[i] = slope_item(args[7 + i / 2], i % 2)) == NULL) {
      goto done;
    }
  }
  for (int i = 0; bends != NULL && i < 6; i++) {
    PyObject *pair = PySequence_GetItem(bends, i / 2);
    seconds[i] = pair ? slope_item(pair, i % 2) : NULL;
    Py_XDECREF(pair);
    if (seconds[i] == NULL) {
      goto done;
    }
  }
  /* the BatPath part */
  Vec middle = {0.25 * (k0.x + e0.x + k1.x + e1.x), 0.25 * (k0.y + e0.y + k1.y + e1.y),
                0.25 * (k0.z + e0.z + k1.z + e1.z)};
  if ((centre = vec_tuple(middle)) == NULL) {
    goto done;
  }
  double radius = -INFINITY;
  for (int i = 0; i < 4; i++) {
    double d = python_dist(ends[i], centre);
    if (PyErr_Occurred()) {
      goto done;
    }
    if (i == 0 || d > radius) {
      radius = d;
    }
  }
  double h = t1 - t0;
  if (PyObject_SetAttr(path, piece_names[PIECE_T0], t0_object) < 0 ||
      PyObject_SetAttr(path, piece_names[PIECE_T1], t1_object) < 0 ||
      !set_number(path, piece_names[PIECE_H], h) ||
      PyObject_SetAttr(path, c2_own_names[C2_SAMPLE0], sample0) < 0 ||
      PyObject_SetAttr(path, c2_own_names[C2_SAMPLE1], sample1) < 0 ||
      PyObject_SetAttr(path, path_names[0], centre) < 0) {
    goto done;
  }
  /* the knob, the turn and the length pieces */
  Vec rotation = rotation_to(axis0, axis1);
  PyObject *call[7];
  if ((knob = bare_instance(args[1])) == NULL || (turn = bare_instance(args[1])) == NULL ||
      (length = bare_instance(args[2])) == NULL ||
      (origin = vec_tuple((Vec){0.0, 0.0, 0.0})) == NULL ||
      (closing = vec_tuple(rotation)) == NULL || (reference = vec_tuple(axis0)) == NULL) {
    goto done;
  }
  Py_ssize_t count = bends != NULL ? 9 : 7;
  PyObject *knob_call[9] = {knob, t0_object, t1_object, ends[0], ends[2], slopes[0], slopes[1],
                            seconds[0], seconds[1]};
  PyObject *made = py_point_path_init(NULL, knob_call, count);
  if (made == NULL) {
    goto done;
  }
  Py_DECREF(made);
  PyObject *turn_call[9] = {turn, t0_object, t1_object, origin, closing, slopes[2], slopes[3],
                            seconds[2], seconds[3]};
  made = py_point_path_init(NULL, turn_call, count);
  if (made == NULL) {
    goto done;
  }
  Py_DECREF(made);
  if (!fill_angle_cubic(length, t0_object, t1_object, t0, t1, length0, length1, slopes[4],
                        slopes[5], bends ? seconds[4] : Py_None, bends ? seconds[5] : Py_None)) {
    goto done;
  }
  double lever = length1 > length0 ? length1 : length0;
  double angle = sqrt(rotation.x * rotation.x + rotation.y * rotation.y +
                      rotation.z * rotation.z);
  if (PyObject_SetAttr(path, knob_name, knob) < 0 ||
      PyObject_SetAttr(path, c2_path_names[0], turn) < 0 ||
      PyObject_SetAttr(path, c2_path_names[1], length) < 0 ||
      PyObject_SetAttr(path, c2_path_names[2], reference) < 0 ||
      !set_number(path, c2_own_names[C2_LEVER], lever) ||
      !set_number(path, c2_own_names[C2_ANGLE], angle)) {
    goto done;
  }
  call[0] = knob, call[1] = turn, call[2] = length, call[3] = t0_object, call[4] = t1_object;
  spread = py_c2_deviation(NULL, call, 5);
  double grown = spread ? PyFloat_AsDouble(spread) : NAN;
  if (spread == NULL || PyErr_Occurred() ||
      PyObject_SetAttr(path, c2_own_names[C2_SPREAD], spread) < 0 ||
      !set_number(path, path_names[1], radius + grown)) {
    goto done;
  }
  result = Py_NewRef(Py_None);
done:
  for (int i = 0; i < 4; i++) {
    Py_XDECREF(ends[i]);
  }
  for (int i = 0; i < 6; i++) {
    Py_XDECREF(slopes[i]);
    Py_XDECREF(seconds[i]);
  }
  Py_XDECREF(centre);
  Py_XDECREF(knob);
  Py_XDECREF(turn);
  Py_XDECREF(length);
  Py_XDECREF(origin);
  Py_XDECREF(closing);
  Py_XDECREF(reference);
  Py_XDECREF(spread);
  return result;
}

/* whether flag i of a sequence is true: 1, 0, or -1 with an exception */
static inline int flag_at(PyObject *list, Py_ssize_t i)
{
  return PyObject_IsTrue(PySequence_Fast_GET_ITEM(list, i));
}

/*
 * reach_back(times, breaks, first, stop, max_gap, span, most) -> the first sample of a window
 * of a stream's samples ending at stop - 1, reached back from ``first``
 * (core.detector.fitting.widened, flight_window): one sample further while there is one
 * before, ``first`` does not start a segment (``breaks[first]``), the window holds fewer than
 * ``most`` samples, the step before ``first`` is at most max_gap and the sample before is at
 * most ``span`` before the newest (times in s). IndexError: first or stop outside the samples.
 */
static PyObject *py_reach_back(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t first, stop, most;
  double max_gap, span;
  if (nargs != 7 || !read_index(args[2], &first) || !read_index(args[3], &stop) ||
      !read_number(args[4], &max_gap) || !read_number(args[5], &span) ||
      !read_index(args[6], &most)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError,
                      "reach_back(times, breaks, first, stop, max_gap, span, most)");
    }
    return NULL;
  }
  PyObject *times = PySequence_Fast(args[0], "times must be a sequence");
  PyObject *breaks = times ? PySequence_Fast(args[1], "breaks must be a sequence") : NULL;
  PyObject *result = NULL;
  if (breaks == NULL) {
    goto done;
  }
  Py_ssize_t n = PySequence_Fast_GET_SIZE(times);
  if (first < 0 || stop > n || first >= stop || PySequence_Fast_GET_SIZE(breaks) != n) {
    PyErr_SetString(PyExc_IndexError, "reach_back: first or stop outside the samples");
    goto done;
  }
  double newest = item_double(PySequence_Fast_GET_ITEM(times, stop - 1));
  double here = item_double(PySequence_Fast_GET_ITEM(times, first));
  while (!PyErr_Occurred() && first > 0 && stop - first < most) {
    int broken = flag_at(breaks, first);
    if (broken != 0) {
      break;
    }
    double before = item_double(PySequence_Fast_GET_ITEM(times, first - 1));
    if (!(here - before <= max_gap) || !(newest - before <= span)) {
      break;
    }
    first--;
    here = before;
  }
  if (!PyErr_Occurred()) {
    result = PyLong_FromSsize_t(first);
  }
done:
  Py_XDECREF(times);
  Py_XDECREF(breaks);
  return result;
}

/*
 * c2_window(times, breaks, k, max_gap, look_ahead, size) -> the range of a stream's samples a
 * c2 fit of interval k takes (core.detector.fitting.c2_window): up to look_ahead samples
 * after its closing frame, back to ``size`` in all, none across a break (``breaks[i]``: sample
 * i starts a segment) or a step longer than max_gap (s). IndexError: k outside the samples.
 */
/*
 * The samples [*first, *last] of c2_window(times, breaks, k, max_gap, look_ahead, size) (fast
 * sequences of one length n, 0 <= k < n); false with an exception (a stamp or break that is
 * not a number or flag).
 */
static bool c2_window_bounds(PyObject *times, PyObject *breaks, Py_ssize_t k, double max_gap,
                             Py_ssize_t look_ahead, Py_ssize_t size, Py_ssize_t *first_out,
                             Py_ssize_t *last_out)
{
  Py_ssize_t n = PySequence_Fast_GET_SIZE(times);
  Py_ssize_t last = k + 1, end = k + 1 + look_ahead < n - 1 ? k + 1 + look_ahead : n - 1;
  int broken = 0;
  while (last < end) {
    if ((broken = flag_at(breaks, last + 1)) != 0) {
      break;
    }
    double step = item_double(PySequence_Fast_GET_ITEM(times, last + 1)) -
                  item_double(PySequence_Fast_GET_ITEM(times, last));
    if (PyErr_Occurred() || !(step <= max_gap)) {
      break;
    }
    last++;
  }
  Py_ssize_t first = k, start = last - size + 1 > 0 ? last - size + 1 : 0;
  while (broken >= 0 && !PyErr_Occurred() && first > start) {
    if ((broken = flag_at(breaks, first)) != 0) {
      break;
    }
    double step = item_double(PySequence_Fast_GET_ITEM(times, first)) -
                  item_double(PySequence_Fast_GET_ITEM(times, first - 1));
    if (PyErr_Occurred() || !(step <= max_gap)) {
      break;
    }
    first--;
  }
  *first_out = first;
  *last_out = last;
  return !PyErr_Occurred();
}

static PyObject *py_c2_window(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t k, look_ahead, size;
  double max_gap;
  if (nargs != 6 || !read_index(args[2], &k) ||
      !read_number(args[3], &max_gap) ||
      !read_index(args[4], &look_ahead) ||
      !read_index(args[5], &size)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "c2_window(times, breaks, k, max_gap, look_ahead, size)");
    }
    return NULL;
  }
  PyObject *times = PySequence_Fast(args[0], "times must be a sequence");
  PyObject *breaks = times ? PySequence_Fast(args[1], "breaks must be a sequence") : NULL;
  PyObject *result = NULL;
  if (breaks == NULL) {
    goto done;
  }
  Py_ssize_t n = PySequence_Fast_GET_SIZE(times);
  if (k < 0 || k >= n || PySequence_Fast_GET_SIZE(breaks) != n) {
    PyErr_SetString(PyExc_IndexError, "c2_window: k outside the samples");
    goto done;
  }
  Py_ssize_t first, last;
  if (c2_window_bounds(times, breaks, k, max_gap, look_ahead, size, &first, &last)) {
    result = PyObject_CallFunction((PyObject *)&PyRange_Type, "nn", first, last + 1);
  }
done:
  Py_XDECREF(times);
  Py_XDECREF(breaks);
  return result;
}

/*
 * bat_samples(cls, knob, tip, position, quaternion, first, last) -> [cls(knob[i], tip[i],
 * position[i], quaternion[i]) for i in first .. last - 1]: a chunk's bat samples as the streams
 * keep them (core.detector.chunks.fast_forward), each field a tuple of floats; the arrays
 * contiguous float64, (m, 3) three times and (m, 4). A class with __slots__ for the four fields
 * (core.motion.BatSample, a frozen dataclass) is filled in straight, as its own __init__ fills
 * it; another is called. ValueError: other arrays, or rows outside them.
 */
static PyObject *bat_sample_list(PyObject *cls, PyObject *const *arrays, Py_ssize_t first,
                                 Py_ssize_t last)
{
  PyTypeObject *type = (PyTypeObject *)cls;
  static const int widths[4] = {3, 3, 3, 4};
  PyObject *names[4] = {knob_name, tip_name, position_name, quaternion_name};
  Py_buffer views[4];
  int viewed = 0;
  PyObject *result = NULL;
  Py_ssize_t rows = -1;
  for (; viewed < 4; viewed++) {
    Py_ssize_t count;
    if (!get_doubles(arrays[viewed], &views[viewed], &count, "bat_samples", false)) {
      goto done;
    }
    if (count % widths[viewed] != 0 || (rows >= 0 && count / widths[viewed] != rows)) {
      viewed++;
      PyErr_SetString(PyExc_ValueError,
                      "bat_samples: arrays of (m, 3), (m, 3), (m, 3) and (m, 4)");
      goto done;
    }
    rows = count / widths[viewed];
  }
  if (first < 0 || last < first || last > rows) {
    PyErr_SetString(PyExc_ValueError, "bat_samples: rows outside the arrays");
    goto done;
  }
  /* the fields' slots (slot_offset; else -1: the class is called) */
  Py_ssize_t offsets[4];
  for (int f = 0; f < 4; f++) {
    if (!slot_offset(cls, names[f], &offsets[f])) {
      PyErr_Clear(); /* (no such attribute: the class is called) */
      offsets[f] = -1;
    }
  }
  bool direct = offsets[0] >= 0 && offsets[1] >= 0 && offsets[2] >= 0 && offsets[3] >= 0;
  result = PyList_New(last - first);
  for (Py_ssize_t i = first; result != NULL && i < last; i++) {
    PyObject *fields[4] = {NULL, NULL, NULL, NULL};
    bool ok = true;
    for (int f = 0; f < 4; f++) {
      const double *x = (const double *)views[f].buf + widths[f] * i;
      fields[f] = ok ? float_tuple(x, widths[f]) : NULL;
      ok = ok && fields[f] != NULL;
    }
    PyObject *sample = NULL;
    if (ok && direct) {
      sample = type->tp_alloc(type, 0);
      for (int f = 0; sample != NULL && f < 4; f++) {
        *(PyObject **)((char *)sample + offsets[f]) = fields[f]; /* stolen */
        fields[f] = NULL;
      }
    } else if (ok) {
      sample = PyObject_CallFunctionObjArgs(cls, fields[0], fields[1], fields[2], fields[3],
                                            NULL);
    }
    for (int f = 0; f < 4; f++) {
      Py_XDECREF(fields[f]);
    }
    if (sample == NULL) {
      Py_CLEAR(result);
      break;
    }
    PyList_SET_ITEM(result, i - first, sample);
  }
done:
  release_views(views, viewed);
  return result;
}

static PyObject *py_bat_samples(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t first, last;
  if (nargs != 7 || !PyType_Check(args[0]) || !read_index(args[5], &first) ||
      !read_index(args[6], &last)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError,
                      "bat_samples(cls, knob, tip, position, quaternion, first, last)");
    }
    return NULL;
  }
  return bat_sample_list(args[0], args + 1, first, last);
}

/* a bat sample's length, math.dist(tip, knob) (NAN with an exception) */
static double bat_length(PyObject *sample)
{
  Vec knob, direction;
  double length;
  return bat_axis(sample, &knob, &direction, &length) ? length : NAN;
}

/* item i of a list of floats (NAN with an exception) */
static double list_double(PyObject *list, Py_ssize_t i)
{
  return item_double(PyList_GET_ITEM(list, i));
}

/* appends a float to a list */
static bool append_double(PyObject *list, double x)
{
  PyObject *item = PyFloat_FromDouble(x);
  bool ok = item != NULL && PyList_Append(list, item) == 0;
  Py_XDECREF(item);
  return ok;
}

/*
 * The c2 far test's per-sample numbers of a stream (core.detector.broadphase.c2.c2_jump_bulge),
 * appended to the lists steps (times[m] - times[m - 1], 0.0 at 0) up to sample last and jumps
 * (the chord velocities' jump at sample m, of the ball, or of the bat's knob plus the same of
 * its length, math.dist(tip, knob), each sample's once) up to last - 1, the entries more than
 * `reach` before last not yet there NaN; the same operations in the same order as the Python
 * it replaced (** 2 as libm's pow). False with an exception (TypeError: not samples).
 */
static bool fill_jump_lists(PyObject *times, PyObject *values, PyObject *steps,
                            PyObject *jumps, Py_ssize_t last, Py_ssize_t reach, bool bat)
{
  Py_ssize_t skip = last - reach;
  while (PyList_GET_SIZE(steps) < skip) {
    if (!append_double(steps, NAN)) {
      return false;
    }
  }
  while (PyList_GET_SIZE(jumps) < skip) {
    if (!append_double(jumps, NAN)) {
      return false;
    }
  }
  for (Py_ssize_t m = PyList_GET_SIZE(steps); m <= last; m++) {
    double step = m ? list_double(times, m) - list_double(times, m - 1) : 0.0;
    if (PyErr_Occurred() || !append_double(steps, step)) {
      return false;
    }
  }
  double length[3] = {NAN, NAN, NAN}; /* samples m - 1, m, m + 1 (the bat's) */
  Py_ssize_t known = -1;              /* length[] holds m - 1 .. m + 1 for m == known */
  for (Py_ssize_t m = PyList_GET_SIZE(jumps); m < last; m++) {
    if (m == 0) {
      if (!append_double(jumps, 0.0)) {
        return false;
      }
      continue;
    }
    double h0 = list_double(steps, m), h1 = list_double(steps, m + 1), stretch = 0.0;
    PyObject *samples[3] = {PyList_GET_ITEM(values, m - 1), PyList_GET_ITEM(values, m),
                            PyList_GET_ITEM(values, m + 1)};
    Vec p[3];
    if (bat) {
      if (known == m - 1) {
        length[0] = length[1], length[1] = length[2];
        length[2] = bat_length(samples[2]);
      } else {
        for (int i = 0; i < 3; i++) {
          length[i] = bat_length(samples[i]);
        }
      }
      known = m;
      stretch = fabs((length[2] - length[1]) / h1 - (length[1] - length[0]) / h0);
    }
    for (int i = 0; i < 3 && !PyErr_Occurred(); i++) {
      PyObject *point = bat ? PyObject_GetAttr(samples[i], knob_name) : Py_NewRef(samples[i]);
      if (point != NULL && !read_vec(point, &p[i])) {
        PyErr_SetString(PyExc_TypeError, "c2_jump_bulge: points of 3 numbers");
      }
      Py_XDECREF(point);
    }
    if (PyErr_Occurred()) {
      return false;
    }
    /* (Python's ** 2: libm's pow, squared_power) */
    double dx = (p[2].x - p[1].x) / h1 - (p[1].x - p[0].x) / h0;
    double dy = (p[2].y - p[1].y) / h1 - (p[1].y - p[0].y) / h0;
    double dz = (p[2].z - p[1].z) / h1 - (p[1].z - p[0].z) / h0;
    double jump = stretch + sqrt(pow(dx, squared_power) + pow(dy, squared_power) +
                                 pow(dz, squared_power));
    if (!append_double(jumps, jump)) {
      return false;
    }
  }
  return true;
}

/* the longest and shortest of steps[first + 1 .. last] (Python's max and min: the first of
 * equals, a NaN kept only where it comes first) */
static void step_extremes(PyObject *steps, Py_ssize_t first, Py_ssize_t last, double *longest,
                          double *shortest)
{
  *longest = *shortest = list_double(steps, first + 1);
  for (Py_ssize_t m = first + 2; m <= last; m++) {
    double step = list_double(steps, m);
    if (step > *longest) {
      *longest = step;
    }
    if (step < *shortest) {
      *shortest = step;
    }
  }
}

/*
 * c2_jump_bulge(times, values, breaks, steps, jumps, k, look_ahead, size, max_gap, bat,
 * constants) -> the bound (m) or None: core.detector.broadphase.c2.c2_jump_bulge (its docstring
 * says what it bounds), the same operations in the same order: the lists steps and jumps (the
 * stream's kept per-sample numbers) filled as far as the window reaches, then over the
 * samples a full window could hold (or c2_window's own where their steps are uneven) the
 * longest step times the sum of C2_JUMP_BEFORE[a] jumps[k - a] (from 0.0, in order) plus the
 * look-ahead terms; None where the steps are more than the ratio apart. constants:
 * (C2_STEP_RATIO, _AFTER_ONE, _AFTER_TWO, C2_JUMP_BEFORE). TypeError: not lists or samples;
 * IndexError: k's interval beyond the samples.
 */
static PyObject *py_c2_jump_bulge(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t k, look_ahead, size;
  double max_gap, ratio, after_one, after_two;
  int bat;
  PyObject *before = NULL;
  if (nargs != 11 || !PyList_Check(args[0]) || !PyList_Check(args[1]) ||
      !PyList_Check(args[2]) || !PyList_Check(args[3]) || !PyList_Check(args[4]) ||
      !read_index(args[5], &k) || !read_index(args[6], &look_ahead) ||
      !read_index(args[7], &size) || !read_number(args[8], &max_gap) ||
      (bat = PyObject_IsTrue(args[9])) < 0 || !PyTuple_Check(args[10]) ||
      !PyArg_ParseTuple(args[10], "dddO!", &ratio, &after_one, &after_two, &PyTuple_Type,
                        &before)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "c2_jump_bulge(times, values, breaks, steps, jumps, k, "
                                       "look_ahead, size, max_gap, bat, constants): lists");
    }
    return NULL;
  }
  PyObject *times = args[0], *values = args[1], *breaks = args[2], *steps = args[3];
  PyObject *jumps = args[4];
  Py_ssize_t n = PyList_GET_SIZE(times);
  if (k < 0 || k + 1 >= n || PyList_GET_SIZE(values) != n || PyList_GET_SIZE(breaks) != n) {
    PyErr_SetString(PyExc_IndexError, "c2_jump_bulge: interval k beyond the samples");
    return NULL;
  }
  Py_ssize_t first = k + 2 - size > 0 ? k + 2 - size : 0;
  Py_ssize_t last = k + 1 + look_ahead < n - 1 ? k + 1 + look_ahead : n - 1;
  if (PyList_GET_SIZE(jumps) < last &&
      !fill_jump_lists(times, values, steps, jumps, last, size + look_ahead + 1, bat)) {
    return NULL;
  }
  if (PyList_GET_SIZE(steps) <= last || PyList_GET_SIZE(jumps) < last) {
    PyErr_SetString(PyExc_IndexError, "c2_jump_bulge: steps and jumps shorter than the window");
    return NULL;
  }
  double longest, shortest;
  step_extremes(steps, first, last, &longest, &shortest);
  if (longest > ratio * shortest) {
    if (!c2_window_bounds(times, breaks, k, max_gap, look_ahead, size, &first, &last)) {
      return NULL;
    }
    step_extremes(steps, first, last, &longest, &shortest);
    if (longest > ratio * shortest) {
      Py_RETURN_NONE;
    }
  }
  double bound = 0.0;
  Py_ssize_t count = PyTuple_GET_SIZE(before);
  for (Py_ssize_t a = 0; a < count && k - a > first; a++) {
    bound += PyFloat_AsDouble(PyTuple_GET_ITEM(before, a)) * list_double(jumps, k - a);
  }
  if (last > k + 1) {
    bound += after_one * list_double(jumps, k + 1);
    if (last > k + 2) {
      bound += after_two * (2.0 * list_double(jumps, k + 1) + list_double(jumps, k + 2));
    }
  }
  if (PyErr_Occurred()) {
    return NULL;
  }
  return PyFloat_FromDouble(longest * bound);
}

/* the attribute names fast_forward_streams reads and sets (interned at import) */
enum {
  FF_COUNTS, FF_PRE, FF_STARTS, FF_TIMES, FF_STAMPS, FF_VALUES, FF_BREAKS, FF_TURNS, FF_ALIGNED,
  FF_NOISE, FF_SPEED_DROPS, FF_PATH_KEY, FF_MEDIANS, FF_TAKE_RUN, FF_SIGMA, FF_UPDATE,
  FF_UPDATE_AT, FF_NAMES
};
static const char *const ff_attributes[FF_NAMES] = {
    "counts", "pre",   "starts",      "times",    "stamps",      "values", "breaks",
    "turns",  "aligned", "noise", "speed_drops", "path_key", "medians", "take_run", "sigma",
    "update", "update_at"};
static PyObject *ff_names[FF_NAMES];
static PyObject *zero_turn; /* (0.0, 0.0, 0.0, 0.0): a segment's first cumulative turn */

/* item i of a sequence of ints (a plan's list or memoryview) as an index; false with an error */
static bool index_at(PyObject *sequence, Py_ssize_t i, Py_ssize_t *out)
{
  PyObject *item = PySequence_GetItem(sequence, i);
  if (item == NULL) {
    return false;
  }
  bool ok = read_index(item, out);
  Py_DECREF(item);
  return ok;
}

/* item s of a plan attribute that holds one per stream (new reference; NULL with an error) */
static PyObject *stream_item(PyObject *plan, int name, int s)
{
  PyObject *pair = PyObject_GetAttr(plan, ff_names[name]);
  PyObject *item = pair ? PySequence_GetItem(pair, s) : NULL;
  Py_XDECREF(pair);
  return item;
}

/*
 * appends items [c, b) of a contiguous int64 or float64 array to a list, as Python numbers;
 * `last` (if not NULL) is set to item b - 1 of an int64 array (b > 0)
 */
static bool append_numbers(PyObject *list, PyObject *array, Py_ssize_t c, Py_ssize_t b,
                           bool integers, long long *last)
{
  Py_buffer view;
  if (PyObject_GetBuffer(array, &view, PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) < 0) {
    return false;
  }
  bool ok = view.itemsize == 8 && view.format != NULL && strlen(view.format) == 1 &&
            strchr(integers ? "lq" : "d", view.format[0]) != NULL && b <= view.len / 8;
  if (!ok) {
    PyErr_SetString(PyExc_ValueError, "fast_forward_streams: a plan's stamps must be int64 "
                                      "and its times float64, holding the samples taken");
  }
  for (Py_ssize_t i = c; ok && i < b; i++) {
    PyObject *item = integers ? PyLong_FromLongLong(((const long long *)view.buf)[i])
                              : PyFloat_FromDouble(((const double *)view.buf)[i]);
    ok = item != NULL && PyList_Append(list, item) == 0;
    Py_XDECREF(item);
  }
  if (ok && last != NULL) {
    *last = ((const long long *)view.buf)[b - 1];
  }
  PyBuffer_Release(&view);
  return ok;
}

/* appends `count` references to one object to a list */
static bool append_repeated(PyObject *list, PyObject *item, Py_ssize_t count)
{
  for (Py_ssize_t i = 0; i < count; i++) {
    if (PyList_Append(list, item) < 0) {
      return false;
    }
  }
  return true;
}

/* appends a list's items to another */
static bool append_all(PyObject *list, PyObject *items)
{
  Py_ssize_t n = PyList_GET_SIZE(list);
  return PyList_SetSlice(list, n, n, items) == 0;
}

/* the widest window of the noise estimate's residuals (samples) */
#define MAX_SPAN 9

/* the newest up to MAX_SPAN - 1 items of a list (new reference) */
static PyObject *newest_before(PyObject *list)
{
  Py_ssize_t n = PyList_GET_SIZE(list);
  return PyList_GetSlice(list, n > MAX_SPAN - 1 ? n - (MAX_SPAN - 1) : 0, n);
}

/*
 * The noise estimator of stream s takes a run's samples a .. b - 1 before they are appended
 * (NoiseEstimate.take_points: each of its medians' take_run, with the stream's newest
 * MAX_SPAN - 1 samples, of which its
 * windows take what they reach: their stamps, points or
 * poses' positions, and breaks; none with `fresh`: sample a starts a segment); the stream's
 * estimate becomes its answer.
 */
static bool take_run_noise(PyObject *estimator, PyObject *stream, PyObject *plan, int s,
                           Py_ssize_t a, Py_ssize_t b, Py_ssize_t pre, PyObject *lists[3],
                           bool fresh)
{
  PyObject *values = stream_item(plan, FF_VALUES, s);
  PyObject *positions = values == NULL || s == 0 ? values : PySequence_GetItem(values, 2);
  if (s == 1) {
    Py_XDECREF(values);
  }
  PyObject *times = stream_item(plan, FF_TIMES, s);
  PyObject *old_times = fresh ? PyList_New(0) : newest_before(lists[0]);
  PyObject *old_values = fresh ? PyList_New(0) : newest_before(lists[1]);
  PyObject *old_breaks = fresh ? PyList_New(0) : newest_before(lists[2]);
  PyObject *old_points = NULL, *run_times = NULL, *run_points = NULL, *result = NULL;
  if (positions == NULL || times == NULL || old_times == NULL || old_values == NULL ||
      old_breaks == NULL) {
    goto done;
  }
  if (s == 0) {
    old_points = Py_NewRef(old_values);
  } else {
    Py_ssize_t n = PyList_GET_SIZE(old_values);
    old_points = PyList_New(n);
    for (Py_ssize_t i = 0; old_points != NULL && i < n; i++) {
      PyObject *position = PyObject_GetAttr(PyList_GET_ITEM(old_values, i), position_name);
      if (position == NULL) {
        Py_CLEAR(old_points);
        break;
      }
      PyList_SET_ITEM(old_points, i, position);
    }
  }
  run_times = old_points ? PySequence_GetSlice(times, a, b) : NULL;
  run_points = run_times ? PySequence_GetSlice(positions, a - pre, b - pre) : NULL;
  if (run_points != NULL) {
    /* each of the estimator's medians takes the run (NoiseEstimate.take_points without its
     * conversions: the plan's arrays are contiguous float64 already), then its estimate */
    PyObject *medians = PyObject_GetAttr(estimator, ff_names[FF_MEDIANS]);
    PyObject *each = medians ? PySequence_Fast(medians, "an estimator's medians") : NULL;
    bool taken = each != NULL;
    for (Py_ssize_t i = 0; taken && i < PySequence_Fast_GET_SIZE(each); i++) {
      PyObject *done_run = PyObject_CallMethodObjArgs(
          PySequence_Fast_GET_ITEM(each, i), ff_names[FF_TAKE_RUN], old_times, old_points,
          old_breaks, run_times, run_points, NULL);
      taken = done_run != NULL;
      Py_XDECREF(done_run);
    }
    Py_XDECREF(each);
    Py_XDECREF(medians);
    result = taken ? PyObject_GetAttr(estimator, ff_names[FF_SIGMA]) : NULL;
  }
done:
  Py_XDECREF(positions);
  Py_XDECREF(times);
  Py_XDECREF(old_times);
  Py_XDECREF(old_values);
  Py_XDECREF(old_breaks);
  Py_XDECREF(old_points);
  Py_XDECREF(run_times);
  Py_XDECREF(run_points);
  bool ok = result != NULL && PyObject_SetAttr(stream, ff_names[FF_NOISE], result) == 0;
  Py_XDECREF(result);
  return ok;
}

/*
 * The newest `trailing` samples of a stream (a run's after record_after), taken one by one by
 * its estimator (NoiseEstimate.update_at, each as if it were the newest), each estimate kept in
 * stream.aligned['noise'] (core.detector.noise.ESTIMATES: None for the samples before them that
 * have none), the stream's noise the newest. False with an exception.
 */
static bool record_trailing(PyObject *estimator, PyObject *stream, Py_ssize_t size,
                            Py_ssize_t trailing)
{
  PyObject *aligned = PyObject_GetAttr(stream, ff_names[FF_ALIGNED]);
  if (aligned == NULL) {
    return false;
  }
  PyObject *kept = PyDict_GetItemWithError(aligned, ff_names[FF_NOISE]); /* borrowed */
  if (kept == NULL && !PyErr_Occurred()) {
    kept = PyList_New(0);
    if (kept != NULL && PyDict_SetItem(aligned, ff_names[FF_NOISE], kept) < 0) {
      Py_CLEAR(kept);
    }
    Py_XDECREF(kept); /* (the dict holds it) */
  }
  Py_DECREF(aligned); /* (the stream holds it) */
  if (kept == NULL) {
    return false;
  }
  if (!PyList_Check(kept) || PyList_GET_SIZE(kept) > size - trailing) {
    PyErr_SetString(PyExc_ValueError, "fast_forward_streams: a stream's kept noise estimates "
                                      "must be a list no longer than its samples before the run");
    return false;
  }
  while (PyList_GET_SIZE(kept) < size - trailing) {
    if (PyList_Append(kept, Py_None) < 0) {
      return false;
    }
  }
  PyObject *estimate = NULL;
  for (Py_ssize_t j = size - trailing; j < size; j++) {
    PyObject *index = PyLong_FromSsize_t(j);
    Py_XDECREF(estimate);
    estimate = index ? PyObject_CallMethodObjArgs(estimator, ff_names[FF_UPDATE_AT], stream,
                                                  index, NULL)
                     : NULL;
    Py_XDECREF(index);
    if (estimate == NULL || PyList_Append(kept, estimate) < 0) {
      Py_XDECREF(estimate);
      return false;
    }
  }
  bool ok = estimate == NULL || PyObject_SetAttr(stream, ff_names[FF_NOISE], estimate) == 0;
  Py_XDECREF(estimate);
  return ok;
}

/*
 * One stream's part of a fast-forward (fast_forward_streams): the run's samples appended (those
 * its trim keeps), its noise estimate, its trim. Adds the samples it took to *taken and raises
 * *newest to the newest stamp taken. False with an exception.
 */
static bool forward_stream(PyObject *plan, int s, Py_ssize_t pos, Py_ssize_t end,
                           PyObject *stream, bool walk, bool stop, PyObject *noise,
                           double record_after, Py_ssize_t ahead, PyObject *sample_class,
                           Py_ssize_t *taken, long long *newest)
{
  enum { TIMES, VALUES, BREAKS, STAMPS, TURNS, LISTS };
  static const int list_names[LISTS] = {FF_TIMES, FF_VALUES, FF_BREAKS, FF_STAMPS, FF_TURNS};
  PyObject *lists[LISTS] = {NULL, NULL, NULL, NULL, NULL};
  PyObject *counts = NULL, *starts = NULL, *pre_object = NULL, *estimator = NULL;
  PyObject *flags_object = NULL;
  Py_buffer flags_view;
  bool flags_held = false, ok = false;
  for (int i = 0; i < LISTS; i++) {
    lists[i] = PyObject_GetAttr(stream, ff_names[list_names[i]]);
    if (lists[i] == NULL) {
      goto done;
    }
    if (!PyList_Check(lists[i])) {
      PyErr_SetString(PyExc_TypeError, "fast_forward_streams: a stream's samples are lists");
      goto done;
    }
  }
  counts = stream_item(plan, FF_COUNTS, s);
  starts = counts ? stream_item(plan, FF_STARTS, s) : NULL;
  pre_object = starts ? stream_item(plan, FF_PRE, s) : NULL;
  Py_ssize_t pre, a, b, start = 0;
  if (pre_object == NULL || !read_index(pre_object, &pre) ||
      !(pos ? index_at(counts, pos - 1, &a) : (a = pre, true)) ||
      !index_at(counts, stop ? end : end - 1, &b) ||
      (walk && !index_at(starts, end - 1, &start))) {
    goto done;
  }
  Py_ssize_t kept = PyList_GET_SIZE(lists[TIMES]), trailing = 0;
  /* the trim after the run, counted from the stream's first sample */
  Py_ssize_t cut = walk ? start - (a - kept) : 0;
  if (b > a) {
    Py_ssize_t c = a + cut - kept > a ? a + cut - kept : a;
    /* the run's samples after record_after (s) but the `ahead` first of the stream's (which no
     * sweep reads: an interval after it is swept with the estimate of the sample `ahead` past its
     * closing one, or at the end the newest, the estimator's own) are taken one by one after
     * the trim, each estimate kept for the sweeps that will read it (record_trailing) */
    Py_ssize_t feed_end = b;
    if (noise != Py_None) {
      Py_ssize_t unread = ahead; /* of the stream's samples after record_after */
      for (Py_ssize_t i = kept - 1; i >= 0 && unread > 0; i--) {
        double t = PyFloat_AsDouble(PyList_GET_ITEM(lists[TIMES], i));
        if (t == -1.0 && PyErr_Occurred()) {
          goto done;
        }
        if (!(t > record_after)) {
          break;
        }
        unread--;
      }
      PyObject *run_times = stream_item(plan, FF_TIMES, s);
      if (run_times == NULL) {
        goto done;
      }
      while (feed_end > a) {
        PyObject *item = PySequence_GetItem(run_times, feed_end - 1);
        double t = item ? PyFloat_AsDouble(item) : -1.0;
        Py_XDECREF(item);
        if (PyErr_Occurred()) {
          Py_DECREF(run_times);
          goto done;
        }
        if (!(t > record_after)) {
          break;
        }
        feed_end--;
      }
      Py_DECREF(run_times);
      feed_end = feed_end + unread < b ? feed_end + unread : b;
    }
    /* one sample appended: the estimator takes it after the append (update); else the run's
     * samples at once before it (take_points) */
    bool single = noise != Py_None && feed_end == b && b - a == 1 && c == a;
    trailing = b - feed_end;
    /* where a sample starts a segment (the plan's breaks: a held first sample after a gap,
     * taken with the sample that takes it) */
    flags_object = stream_item(plan, FF_BREAKS, s);
    if (flags_object == NULL ||
        PyObject_GetBuffer(flags_object, &flags_view, PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) < 0) {
      goto done;
    }
    flags_held = true;
    if (flags_view.itemsize != 1 || flags_view.format == NULL ||
        strcmp(flags_view.format, "?") != 0 || flags_view.len < b) {
      PyErr_SetString(PyExc_ValueError, "fast_forward_streams: a plan's breaks must be bool "
                                        "arrays holding the samples taken");
      goto done;
    }
    const bool *flags = (const bool *)flags_view.buf;
    if (noise != Py_None) {
      estimator = PySequence_GetItem(noise, s);
      if (estimator == NULL) {
        goto done;
      }
      /* the run in parts, each from a segment's start (or the run's) to the next's */
      for (Py_ssize_t part = a; !single && part < feed_end;) {
        Py_ssize_t next = part + 1;
        while (next < feed_end && !flags[next]) {
          next++;
        }
        if (!take_run_noise(estimator, stream, plan, s, part, next, pre, lists, flags[part])) {
          goto done;
        }
        part = next;
      }
    }
    PyObject *times = stream_item(plan, FF_TIMES, s);
    bool appended = times != NULL && append_numbers(lists[TIMES], times, c, b, false, NULL);
    Py_XDECREF(times);
    PyObject *stamps = appended ? stream_item(plan, FF_STAMPS, s) : NULL;
    long long stamp = 0;
    appended = stamps != NULL && append_numbers(lists[STAMPS], stamps, c, b, true, &stamp);
    for (Py_ssize_t i = c; appended && i < b; i++) {
      appended = PyList_Append(lists[BREAKS], flags[i] ? Py_True : Py_False) == 0;
    }
    PyObject *values = appended ? stream_item(plan, FF_VALUES, s) : NULL;
    PyObject *made = NULL;
    if (values != NULL && s == 1) {
      PyObject *arrays = PySequence_Fast(values, "fast_forward_streams: a plan's bat arrays");
      if (arrays != NULL && PySequence_Fast_GET_SIZE(arrays) != 4) {
        PyErr_SetString(PyExc_ValueError, "fast_forward_streams: four bat arrays");
      } else if (arrays != NULL) {
        made = bat_sample_list(sample_class, PySequence_Fast_ITEMS(arrays), c - pre, b - pre);
      }
      Py_XDECREF(arrays);
      appended = made != NULL && append_all(lists[VALUES], made);
      for (Py_ssize_t i = c; appended && i < b; i++) { /* (Stream.append's: a segment's first
                                                        * turn is zero) */
        appended = PyList_Append(lists[TURNS], flags[i] ? zero_turn : Py_None) == 0;
      }
    } else if (values != NULL) {
      Py_buffer view;
      Py_ssize_t count;
      appended = get_doubles(values, &view, &count, "fast_forward_streams", false);
      if (appended) {
        if (count < 3 * (b - pre)) {
          PyErr_SetString(PyExc_ValueError, "fast_forward_streams: ball rows outside the plan");
          appended = false;
        } else {
          made = float_rows((const double *)view.buf + 3 * (c - pre), b - c, 3, true);
          appended = made != NULL && append_all(lists[VALUES], made);
        }
        PyBuffer_Release(&view);
      }
    } else {
      appended = false;
    }
    Py_XDECREF(made);
    Py_XDECREF(values);
    Py_XDECREF(stamps);
    if (!appended) {
      goto done;
    }
    if (single) {
      PyObject *estimate = PyObject_CallMethodOneArg(estimator, ff_names[FF_UPDATE], stream);
      bool set = estimate != NULL && PyObject_SetAttr(stream, ff_names[FF_NOISE], estimate) == 0;
      Py_XDECREF(estimate);
      if (!set) {
        goto done;
      }
    }
    *taken += b - a;
    PyObject *zero = PyLong_FromLong(0);
    bool set = zero != NULL && PyObject_SetAttr(stream, ff_names[FF_SPEED_DROPS], zero) == 0;
    Py_XDECREF(zero);
    if (!set) {
      goto done;
    }
    if (stamp > *newest) {
      *newest = stamp;
    }
  }
  if (cut > 0) {
    cut = cut < kept ? cut : kept;
    for (int i = 0; i < LISTS; i++) {
      if (PyList_SetSlice(lists[i], 0, cut, NULL) < 0) {
        goto done;
      }
    }
    PyObject *aligned = PyObject_GetAttr(stream, ff_names[FF_ALIGNED]);
    PyObject *buffers = aligned ? PyDict_Values(aligned) : NULL;
    Py_XDECREF(aligned);
    if (buffers == NULL) {
      goto done;
    }
    for (Py_ssize_t i = 0; i < PyList_GET_SIZE(buffers); i++) {
      if (PySequence_DelSlice(PyList_GET_ITEM(buffers, i), 0, cut) < 0) {
        Py_DECREF(buffers);
        goto done;
      }
    }
    Py_DECREF(buffers);
    if (PyObject_SetAttr(stream, ff_names[FF_PATH_KEY], Py_None) < 0) {
      goto done;
    }
  }
  if (trailing > 0 &&
      !record_trailing(estimator, stream, PyList_GET_SIZE(lists[TIMES]), trailing)) {
    goto done;
  }
  ok = true;
done:
  for (int i = 0; i < LISTS; i++) {
    Py_XDECREF(lists[i]);
  }
  Py_XDECREF(counts);
  Py_XDECREF(starts);
  Py_XDECREF(pre_object);
  Py_XDECREF(estimator);
  if (flags_held) {
    PyBuffer_Release(&flags_view);
  }
  Py_XDECREF(flags_object);
  return ok;
}

/*
 * fast_forward_streams(plan, pos, end, ball, bat, walk, stop, noise, sample_class, record_after,
 *                      ahead) -> (newest stamp taken or 0, samples taken by the ball, by the bat)
 * The streams' part of core.detector.chunks.fast_forward, ball then bat, each as its Python
 * did: the run's samples a .. b - 1 of the plan (b from sample end with `stop`) appended as
 * the streams' lists (stamps as ints, times as floats, ball points as tuples, bat samples
 * made as bat_samples makes them: those the run's trim keeps; a sample's break the plan's
 * `breaks`, a bat's turn zero where it breaks, else None), the noise estimate taken (`noise`:
 * the two NoiseEstimate objects, or None; a segment started in the run taken from its start)
 * of the run's samples up to record_after (s), speed_drops 0, then the trim (`walk`: to the
 * plan's start after the run) of every list and of `aligned`'s, path_key None; then the run's
 * samples after record_after but the stream's `ahead` first there taken one by one, each
 * estimate kept (record_trailing).
 */
static PyObject *py_fast_forward_streams(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t pos, end;
  int walk, stop;
  Py_ssize_t ahead = 0;
  double record_after = nargs == 11 ? PyFloat_AsDouble(args[9]) : 0.0;
  if (nargs != 11 || !read_index(args[1], &pos) || !read_index(args[2], &end) ||
      (walk = PyObject_IsTrue(args[5])) < 0 || (stop = PyObject_IsTrue(args[6])) < 0 ||
      !PyType_Check(args[8]) || (record_after == -1.0 && PyErr_Occurred()) ||
      !read_index(args[10], &ahead)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "fast_forward_streams(plan, pos, end, ball, bat, walk, "
                                       "stop, noise, sample_class, record_after, ahead)");
    }
    return NULL;
  }
  if (ahead < 0) {
    PyErr_SetString(PyExc_ValueError, "fast_forward_streams: ahead must not be negative");
    return NULL;
  }
  if (pos < 0 || end <= pos) {
    PyErr_SetString(PyExc_ValueError, "fast_forward_streams: an empty or negative run");
    return NULL;
  }
  Py_ssize_t taken[2] = {0, 0};
  long long newest = 0;
  for (int s = 0; s < 2; s++) {
    if (!forward_stream(args[0], s, pos, end, args[3 + s], walk, stop, args[7], record_after,
                        ahead, args[8], &taken[s], &newest)) {
      return NULL;
    }
  }
  return Py_BuildValue("Lnn", newest, taken[0], taken[1]);
}

/*
 * The free flight (miss, spread, bend, end, acceleration) through a point stream's samples
 * k - 2 .. k (lists: stamps in s, points of 3 numbers, breaks) at sample k + 1, the operations
 * of the Python it replaced in its order (core.detector.departure.parabola), or None: k < 2, a
 * break at k - 1, k or k + 1, or a step over max_gap (s). Lagrange's weights at t3, the
 * parabola's value there (end), twice the second divided difference (acceleration, m/s^2),
 * math.dist of sample k + 1 from end (miss), 1 plus the squared weights (spread), the bulge
 * |a| h^2 / 8 (bend). A new reference; NULL with TypeError (not points) or IndexError (k + 1
 * beyond the lists).
 */
static PyObject *parabola_of(PyObject *times, PyObject *values, PyObject *breaks, Py_ssize_t k,
                             double max_gap)
{
  if (k + 1 >= PyList_GET_SIZE(times) || k + 1 >= PyList_GET_SIZE(values) ||
      k + 1 >= PyList_GET_SIZE(breaks)) {
    PyErr_SetString(PyExc_IndexError, "parabola: sample k + 1 beyond the lists");
    return NULL;
  }
  if (k < 2) {
    Py_RETURN_NONE;
  }
  for (Py_ssize_t i = k - 1; i <= k + 1; i++) {
    int broken = PyObject_IsTrue(PyList_GET_ITEM(breaks, i));
    if (broken < 0) {
      return NULL;
    }
    if (broken) {
      Py_RETURN_NONE;
    }
  }
  double t0 = list_double(times, k - 2), t1 = list_double(times, k - 1);
  double t2 = list_double(times, k), t3 = list_double(times, k + 1);
  if (PyErr_Occurred()) {
    return NULL;
  }
  double h0 = t1 - t0, h1 = t2 - t1, h = t3 - t2;
  if (h0 > max_gap || h1 > max_gap || h > max_gap) {
    Py_RETURN_NONE;
  }
  Vec p[3];
  for (int i = 0; i < 3; i++) {
    if (!read_vec(PyList_GET_ITEM(values, k - 2 + i), &p[i])) {
      PyErr_SetString(PyExc_TypeError, "parabola: points of 3 numbers");
      return NULL;
    }
  }
  /* Lagrange's weights of the three samples at t3 (they sum to 1) */
  double w0 = (t3 - t1) * h / ((t0 - t1) * (t0 - t2));
  double w1 = (t3 - t0) * h / ((t1 - t0) * (t1 - t2));
  double w2 = 1.0 - w0 - w1;
  double end[3] = {w0 * p[0].x + w1 * p[1].x + w2 * p[2].x,
                   w0 * p[0].y + w1 * p[1].y + w2 * p[2].y,
                   w0 * p[0].z + w1 * p[1].z + w2 * p[2].z};
  /* twice the second divided difference */
  double span = 0.5 * (t2 - t0);
  double acceleration[3] = {((p[2].x - p[1].x) / h1 - (p[1].x - p[0].x) / h0) / span,
                            ((p[2].y - p[1].y) / h1 - (p[1].y - p[0].y) / h0) / span,
                            ((p[2].z - p[1].z) / h1 - (p[1].z - p[0].z) / h0) / span};
  double ax = acceleration[0], ay = acceleration[1], az = acceleration[2];
  double bend = sqrt(ax * ax + ay * ay + az * az) * h * h / 8.0;
  double spread = 1.0 + w0 * w0 + w1 * w1 + w2 * w2;
  PyObject *end_tuple = float_tuple(end, 3);
  PyObject *acceleration_tuple = end_tuple ? float_tuple(acceleration, 3) : NULL;
  PyObject *closing = acceleration_tuple ? PySequence_Tuple(PyList_GET_ITEM(values, k + 1))
                                         : NULL;
  double miss = closing ? python_dist(closing, end_tuple) : NAN;
  PyObject *result = closing && !PyErr_Occurred()
                         ? Py_BuildValue("dddOO", miss, spread, bend, end_tuple, acceleration_tuple)
                         : NULL;
  Py_XDECREF(end_tuple);
  Py_XDECREF(acceleration_tuple);
  Py_XDECREF(closing);
  return result;
}

/* kept_parabola's answer (a new reference, None included; NULL with an exception) for the
 * lists times, values, breaks and the dict aligned */
static PyObject *kept_parabola_of(PyObject *times, PyObject *values, PyObject *breaks,
                                  PyObject *aligned, Py_ssize_t k, double max_gap)
{
  if (k < 2 || k + 1 >= PyList_GET_SIZE(times)) {
    Py_RETURN_NONE;
  }
  PyObject *kept = PyDict_GetItemWithError(aligned, parabolas_name); /* borrowed */
  if (kept == NULL) {
    if (PyErr_Occurred() || (kept = PyList_New(0)) == NULL) {
      return NULL;
    }
    int stored = PyDict_SetItem(aligned, parabolas_name, kept);
    Py_DECREF(kept); /* (the dict holds it) */
    if (stored < 0) {
      return NULL;
    }
  }
  if (!PyList_Check(kept)) {
    PyErr_SetString(PyExc_TypeError, "kept_parabola: aligned['parabolas'] must be a list");
    return NULL;
  }
  if (k < PyList_GET_SIZE(kept)) {
    PyObject *entry = PyList_GET_ITEM(kept, k);
    if (entry != Py_None && PyTuple_Check(entry) && PyTuple_GET_SIZE(entry) == 2 &&
        PyFloat_Check(PyTuple_GET_ITEM(entry, 0)) &&
        PyFloat_AS_DOUBLE(PyTuple_GET_ITEM(entry, 0)) == max_gap) {
      return Py_NewRef(PyTuple_GET_ITEM(entry, 1));
    }
  } else if (!append_repeated(kept, Py_None, k + 1 - PyList_GET_SIZE(kept))) {
    return NULL;
  }
  if (!PyList_Check(values) || !PyList_Check(breaks)) {
    PyErr_SetString(PyExc_TypeError, "kept_parabola: lists of values and breaks");
    return NULL;
  }
  PyObject *found = parabola_of(times, values, breaks, k, max_gap);
  PyObject *entry = found ? Py_BuildValue("(dO)", max_gap, found) : NULL;
  if (entry == NULL || PyList_SetItem(kept, k, entry) < 0) { /* (steals entry) */
    Py_XDECREF(found);
    return NULL;
  }
  return found;
}

/*
 * kept_parabola(times, values, breaks, aligned, k, max_gap) -> the free flight above over
 * interval k of a point stream, kept per interval in aligned["parabolas"] (a list aligned
 * with the samples: (max_gap, answer) at k, None where none was asked) once sample k + 1 is
 * there (core.detector.departure.parabola); None when it is not, or for k < 2.
 */
static PyObject *py_kept_parabola(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t k;
  double max_gap;
  if (nargs != 6 || !PyList_Check(args[0]) || !PyDict_Check(args[3]) ||
      !read_index(args[4], &k) ||
      ((max_gap = PyFloat_AsDouble(args[5])) == -1.0 && PyErr_Occurred())) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError,
                      "kept_parabola(times, values, breaks, aligned, k, max_gap)");
    }
    return NULL;
  }
  return kept_parabola_of(args[0], args[1], args[2], args[3], k, max_gap);
}

typedef struct { /* departure's constants (core.detector.departure) */
  double floor;       /* DEPARTURE_FLOOR (m) */
  double chi_square;  /* DEPARTURE_CHI_SQUARE */
  Py_ssize_t scatter; /* SCATTER_INTERVALS */
  double ratio;       /* SCATTER_RATIO */
  double few[3];      /* FEW_SCATTER_RATIOS: with 1, 2, 3 intervals of scatter */
} DepartureRules;

/*
 * departure's _departed: the parabola of interval k when its closing sample left it (more
 * than the floor, outside the noise's chi-square bound and the scatter of the intervals
 * before: their ratio FEW_SCATTER_RATIOS with one to three of them, SCATTER_RATIO with more;
 * none with no noise told and no interval before to scatter), else None; the Python's
 * operations in its order (the scatter's sum from 0.0). A new reference; NULL with an
 * exception.
 */
static PyObject *departed_of(PyObject *const *lists, PyObject *aligned, Py_ssize_t k,
                             double noise, double max_gap, const DepartureRules *rules)
{
  if (k < 0) {
    Py_RETURN_NONE;
  }
  PyObject *fitted = kept_parabola_of(lists[0], lists[1], lists[2], aligned, k, max_gap);
  if (fitted == NULL || fitted == Py_None) {
    return fitted;
  }
  double miss = PyFloat_AsDouble(PyTuple_GET_ITEM(fitted, 0));
  double spread = PyFloat_AsDouble(PyTuple_GET_ITEM(fitted, 1));
  if (miss <= rules->floor || miss * miss <= rules->chi_square * noise * noise * spread) {
    Py_DECREF(fitted);
    Py_RETURN_NONE;
  }
  double sum = 0.0;
  Py_ssize_t count = 0;
  for (Py_ssize_t j = k - rules->scatter; j < k; j++) {
    if (j < 0) {
      continue;
    }
    PyObject *before = kept_parabola_of(lists[0], lists[1], lists[2], aligned, j, max_gap);
    if (before == NULL) {
      Py_DECREF(fitted);
      return NULL;
    }
    if (before != Py_None) {
      double m = PyFloat_AsDouble(PyTuple_GET_ITEM(before, 0));
      sum += m * m / PyFloat_AsDouble(PyTuple_GET_ITEM(before, 1));
      count++;
    }
    Py_DECREF(before);
  }
  double ratio = count > 3 ? rules->ratio : count ? rules->few[count - 1] : 0.0;
  if (count ? miss * miss <= ratio * spread * sum / (double)count : !(noise > 0.0)) {
    Py_DECREF(fitted);
    Py_RETURN_NONE;
  }
  return fitted;
}

/*
 * leaves_flight(times, values, breaks, aligned, k, noise, max_gap, rules) -> the free flight's
 * parabola when sample k + 1 has departed from it, else None (core.detector.departure
 * .leaves_flight: departed itself, and neither sample k - 1 nor k departed); rules:
 * (DEPARTURE_FLOOR, DEPARTURE_CHI_SQUARE, SCATTER_INTERVALS, SCATTER_RATIO,
 * FEW_SCATTER_RATIOS).
 */
static PyObject *py_leaves_flight(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t k;
  double noise, max_gap;
  DepartureRules rules;
  if (nargs != 8 || !PyList_Check(args[0]) || !PyDict_Check(args[3]) ||
      !read_index(args[4], &k) || !read_number(args[5], &noise) ||
      !read_number(args[6], &max_gap) ||
      !PyArg_ParseTuple(args[7], "ddnd(ddd)", &rules.floor, &rules.chi_square, &rules.scatter,
                        &rules.ratio, &rules.few[0], &rules.few[1], &rules.few[2])) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "leaves_flight(times, values, breaks, aligned, k, "
                                       "noise, max_gap, rules)");
    }
    return NULL;
  }
  PyObject *fitted = departed_of(args, args[3], k, noise, max_gap, &rules);
  for (Py_ssize_t j = k - 1; fitted != NULL && fitted != Py_None && j >= k - 2; j--) {
    PyObject *own = departed_of(args, args[3], j, noise, max_gap, &rules);
    if (own == NULL || own != Py_None) {
      Py_DECREF(fitted);
      fitted = own == NULL ? NULL : Py_NewRef(Py_None);
    }
    Py_XDECREF(own);
  }
  return fitted;
}

/*
 * The noise estimate's residuals (m) of the middle samples of `count` windows of `span` (odd,
 * 3 to MAX_SPAN): the window k is t[k..k+span-1] (s) and p[3k..3(k+span)-1] (m, x y z each);
 * out[3k + a] the (span - 1)-th divided difference of coordinate a on the window's stamps
 * (each weight 1 over the product of its stamp's differences from the others, in stamp
 * order), about the middle sample, added left to right from 0.0, over its noise gain (the
 * root sum of the squared weights, added likewise): the middle sample's residual against the
 * polynomial of degree span - 2 through the others, scaled to the noise's sigma.
 */
static void difference_rows(const double *t, const double *p, int span, Py_ssize_t count,
                            double *out)
{
  for (Py_ssize_t k = 0; k < count; k++) {
    const double *s = t + k, *q = p + 3 * k;
    double w[MAX_SPAN], gain = 0.0;
    for (int i = 0; i < span; i++) {
      double product = 1.0;
      bool started = false;
      for (int o = 0; o < span; o++) {
        if (o != i) { /* (t_i - t_o) multiplied in stamp order, the first as it is */
          product = started ? product * (s[i] - s[o]) : s[i] - s[o];
          started = true;
        }
      }
      w[i] = 1.0 / product;
      gain += w[i] * w[i];
    }
    gain = sqrt(gain);
    for (int a = 0; a < 3; a++) {
      double middle = q[3 * (span / 2) + a], sum = 0.0;
      for (int i = 0; i < span; i++) {
        sum += w[i] * (q[3 * i + a] - middle);
      }
      out[3 * k + a] = sum / gain;
    }
  }
}

/*
 * The residuals of `count` windows of `span` from sample `start` of the samples old (sequences
 * from PySequence_Fast: stamps in s, points in m) then new (`fresh` of them: stamps and
 * (fresh, 3) points, contiguous; or none), difference_rows' (3 per window), in a block of
 * memory the caller frees (PyMem_Free); NULL with an exception (IndexError: a window outside
 * the samples; TypeError: a point that is not 3 numbers).
 */
static double *window_residuals(PyObject *old_times, PyObject *old_points, const double *times,
                                const double *points, Py_ssize_t fresh, int span,
                                Py_ssize_t start, Py_ssize_t count, const char *what,
                                double **residuals)
{
  Py_ssize_t old = PySequence_Fast_GET_SIZE(old_times);
  if (PySequence_Fast_GET_SIZE(old_points) < old) {
    old = PySequence_Fast_GET_SIZE(old_points);
  }
  if (start < 0 || count < 0 || start + count + span - 1 > old + fresh) {
    PyErr_Format(PyExc_IndexError, "%s: a window outside the samples", what);
    return NULL;
  }
  Py_ssize_t n = count + span - 1;
  double *memory = PyMem_Malloc(sizeof(double) * (size_t)(4 * n + 3 * count + 1));
  if (memory == NULL) {
    PyErr_NoMemory();
    return NULL;
  }
  double *t = memory, *p = t + n;
  for (Py_ssize_t i = 0; i < n; i++) {
    Py_ssize_t at = start + i;
    if (at >= old) {
      t[i] = times[at - old];
      memcpy(p + 3 * i, points + 3 * (at - old), 3 * sizeof(double));
      continue;
    }
    t[i] = item_double(PySequence_Fast_GET_ITEM(old_times, at));
    Vec v;
    if (PyErr_Occurred() || !read_vec(PySequence_Fast_GET_ITEM(old_points, at), &v)) {
      if (!PyErr_Occurred()) {
        PyErr_Format(PyExc_TypeError, "%s: a point must be 3 numbers", what);
      }
      PyMem_Free(memory);
      return NULL;
    }
    p[3 * i] = v.x, p[3 * i + 1] = v.y, p[3 * i + 2] = v.z;
  }
  *residuals = p + 3 * n;
  difference_rows(t, p, span, count, *residuals);
  return memory;
}

/* whether a window of residuals may span this many samples (ValueError if not) */
static bool valid_span(Py_ssize_t span)
{
  if (span < 3 || span > MAX_SPAN || span % 2 == 0) {
    PyErr_Format(PyExc_ValueError, "span must be odd, from 3 to %d samples", MAX_SPAN);
    return false;
  }
  return true;
}

/*
 * point_residuals(times, points, start, count, scale, floor[, span]) -> (residuals, small): the
 * noise estimate's residuals (m) of the middle samples of the windows of `span` (5 if not
 * given) from start, start + 1, ... (count of them), three per window (x, y, z;
 * difference_rows), and for each whether scale |residual| < floor. IndexError: a window
 * outside the samples; ValueError: a span that is not odd from 3 to MAX_SPAN.
 */
static PyObject *py_point_residuals(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t start, count, span = 5;
  double scale, floor;
  if ((nargs != 6 && nargs != 7) ||
      !read_index(args[2], &start) ||
      !read_index(args[3], &count) ||
      !read_number(args[4], &scale) || !read_number(args[5], &floor) ||
      (nargs == 7 && !read_index(args[6], &span))) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError,
                      "point_residuals(times, points, start, count, scale, floor[, span])");
    }
    return NULL;
  }
  if (!valid_span(span)) {
    return NULL;
  }
  PyObject *times = PySequence_Fast(args[0], "times must be a sequence");
  PyObject *points = times ? PySequence_Fast(args[1], "points must be a sequence") : NULL;
  PyObject *result = NULL;
  double *memory = NULL, *out = NULL;
  if (points == NULL ||
      (memory = window_residuals(times, points, NULL, NULL, 0, (int)span, start, count,
                                 "point_residuals", &out)) == NULL) {
    goto done;
  }
  PyObject *residuals = float_list(out, (int)(3 * count));
  PyObject *small = residuals ? PyList_New(3 * count) : NULL;
  for (Py_ssize_t i = 0; small != NULL && i < 3 * count; i++) {
    PyList_SET_ITEM(small, i, Py_NewRef(scale * fabs(out[i]) < floor ? Py_True : Py_False));
  }
  if (small != NULL) {
    result = PyTuple_Pack(2, residuals, small);
    Py_DECREF(small);
  }
  Py_XDECREF(residuals);
done:
  PyMem_Free(memory);
  Py_XDECREF(times);
  Py_XDECREF(points);
  return result;
}

/*
 * NoiseMedian(capacity, scale, floor, min_count, rebuild, span=5): tracker_noise auto's running
 * estimate (core.detector.noise.NoiseEstimate), `sigma` = scale times the median of the newest
 * `capacity` residuals' absolute values (m); 0 below `floor`; unchanged (0) while fewer than
 * `min_count` are in. The residuals are kept in a ring in arrival order, their absolute values
 * ascending only while an estimate needs them: where more than half are small (scale |r| <
 * floor, counted as they come and go) the median cannot reach the floor and the estimate is 0
 * without them. Taken up to `rebuild` at once, the sorted values move by a bisection and a
 * memmove each; more at once, they are sorted again when an estimate next needs them. NaN
 * residuals sort last (no crash; such a median is NaN and the estimate 0).
 *
 *   take(residuals) -> sigma: residuals (m) in order
 *   take_points(old_times, old_points, times, points, start, count) -> None: the residuals of
 *       `count` windows of `span` from sample `start` of the samples old (sequences of stamps in
 *       s and points in m) then new (times: contiguous float64 (n,), points (n, 3), or both
 *       None), as point_residuals gives them; IndexError: a window outside the samples
 *   take_run(old_times, old_points, old_breaks, times, points) -> None: take_points over every
 *       whole window of a run of new samples after the stream's newest (its breaks too)
 *   residuals() -> the kept residuals (m), oldest first
 *   take_stream(times, values, breaks[, last]) -> None: the newest sample's residuals
 *       (update's), or sample last's as if it were the newest (update_at's)
 *   sigma: the estimate, set from the residuals held when read (a take sets it no sooner: an
 *       estimate nobody reads is not sorted for)
 *   bounds(times, points, breaks, pre, block, out): upper bounds on the estimate over a chunk
 */
typedef struct {
  PyObject_HEAD
  Py_ssize_t capacity, min_count, rebuild;
  int span;                      /* the samples of a residual's window (odd) */
  double scale, floor, sigma;    /* sigma: the estimate, when `stale` is false */
  bool stale;                    /* residuals taken since sigma was set (median_settle) */
  Py_ssize_t head, count, below; /* the oldest residual's slot, how many, how many are small */
  bool ordered;                  /* whether `sorted` holds the |residuals| ascending */
  double *ring, *sorted;
  unsigned char *small;
} NoiseMedian;

static int ascending(const void *a, const void *b)
{
  double x = *(const double *)a, y = *(const double *)b;
  if (isnan(x) || isnan(y)) {
    return isnan(x) - isnan(y);
  }
  return (x > y) - (x < y);
}

/* the first index of sorted[0..n) not below x (bisect_left; NaN: past the numbers) */
static Py_ssize_t first_not_below(const double *sorted, Py_ssize_t n, double x)
{
  Py_ssize_t lo = 0, hi = n;
  if (isnan(x)) {
    for (lo = n; lo > 0 && isnan(sorted[lo - 1]); lo--) {
    }
    return lo;
  }
  while (lo < hi) {
    Py_ssize_t mid = lo + (hi - lo) / 2;
    if (sorted[mid] < x) {
      lo = mid + 1;
    } else {
      hi = mid;
    }
  }
  return lo;
}

/* the first index of sorted[0..n) above x (bisect_right; NaN: the end) */
static Py_ssize_t first_above(const double *sorted, Py_ssize_t n, double x)
{
  Py_ssize_t lo = 0, hi = n;
  while (lo < hi) {
    Py_ssize_t mid = lo + (hi - lo) / 2;
    if (x < sorted[mid]) {
      hi = mid;
    } else {
      lo = mid + 1;
    }
  }
  return lo;
}

/* take n residuals (m) in order; the estimate is set when next read (median_settle) */
static void median_push(NoiseMedian *m, const double *found, Py_ssize_t n)
{
  Py_ssize_t capacity = m->capacity;
  bool keep = m->ordered && n <= m->rebuild; /* else sorted again when next needed */
  Py_ssize_t first = n > capacity ? n - capacity : 0; /* older ones would leave at once */
  for (Py_ssize_t i = first; i < n; i++) {
    double r = found[i];
    unsigned char flag = m->scale * fabs(r) < m->floor;
    Py_ssize_t slot;
    if (m->count == capacity) { /* the oldest leaves */
      slot = m->head;
      m->head = m->head + 1 == capacity ? 0 : m->head + 1;
      m->below -= m->small[slot];
      if (keep) {
        Py_ssize_t j = first_not_below(m->sorted, capacity, fabs(m->ring[slot]));
        memmove(m->sorted + j, m->sorted + j + 1, sizeof(double) * (size_t)(capacity - 1 - j));
      }
      m->count--;
    } else {
      slot = m->head + m->count;
      slot = slot >= capacity ? slot - capacity : slot;
    }
    m->ring[slot] = r;
    m->small[slot] = flag;
    m->below += flag;
    if (keep) {
      double a = fabs(r);
      Py_ssize_t j = first_above(m->sorted, m->count, a);
      memmove(m->sorted + j + 1, m->sorted + j, sizeof(double) * (size_t)(m->count - j));
      m->sorted[j] = a;
    }
    m->count++;
  }
  m->ordered = keep;
  m->stale = m->stale || n > 0;
}

/* set the estimate from the residuals held, where any came since it was set */
static void median_settle(NoiseMedian *m)
{
  if (!m->stale) {
    return;
  }
  m->stale = false;
  Py_ssize_t capacity = m->capacity;
  if (m->count < m->min_count) {
    return;
  }
  Py_ssize_t middle = m->count / 2;
  if (m->below > middle) { /* the median is at most the middle-th smallest: small */
    m->sigma = 0.0;
    return;
  }
  if (!m->ordered) {
    for (Py_ssize_t i = 0, slot = m->head; i < m->count; i++) {
      m->sorted[i] = fabs(m->ring[slot]);
      slot = slot + 1 == capacity ? 0 : slot + 1;
    }
    qsort(m->sorted, (size_t)m->count, sizeof(double), ascending);
    m->ordered = true;
  }
  double median = m->count % 2 ? m->sorted[middle]
                               : (m->sorted[middle - 1] + m->sorted[middle]) / 2.0;
  double sigma = m->scale * median;
  m->sigma = sigma >= m->floor ? sigma : 0.0;
}

/* take n residuals (m) in order and set the estimate */
static void median_take(NoiseMedian *m, const double *found, Py_ssize_t n)
{
  median_push(m, found, n);
  median_settle(m);
}

static void median_dealloc(NoiseMedian *m)
{
  PyMem_Free(m->ring);
  PyMem_Free(m->sorted);
  PyMem_Free(m->small);
  Py_TYPE(m)->tp_free((PyObject *)m);
}

static PyObject *median_new(PyTypeObject *type, PyObject *args, PyObject *kwargs)
{
  Py_ssize_t capacity, min_count, rebuild, span = 5;
  double scale, floor;
  static char *names[] = {"capacity", "scale", "floor", "min_count", "rebuild", "span", NULL};
  if (!PyArg_ParseTupleAndKeywords(args, kwargs, "nddnn|n", names, &capacity, &scale, &floor,
                                   &min_count, &rebuild, &span) ||
      !valid_span(span)) {
    return NULL;
  }
  if (capacity < 1) {
    PyErr_SetString(PyExc_ValueError, "NoiseMedian: capacity must be at least 1");
    return NULL;
  }
  NoiseMedian *m = (NoiseMedian *)type->tp_alloc(type, 0);
  if (m == NULL) {
    return NULL;
  }
  m->capacity = capacity, m->min_count = min_count, m->rebuild = rebuild;
  m->span = (int)span;
  m->scale = scale, m->floor = floor, m->sigma = 0.0, m->stale = false;
  m->head = m->count = m->below = 0;
  m->ordered = false; /* (sorted when an estimate first needs it: exact samples never do) */
  m->ring = PyMem_Malloc(sizeof(double) * (size_t)capacity);
  m->sorted = PyMem_Malloc(sizeof(double) * (size_t)capacity);
  m->small = PyMem_Malloc((size_t)capacity);
  if (m->ring == NULL || m->sorted == NULL || m->small == NULL) {
    Py_DECREF(m);
    return PyErr_NoMemory();
  }
  return (PyObject *)m;
}

static PyObject *median_take_method(NoiseMedian *m, PyObject *arg)
{
  PyObject *found = PySequence_Fast(arg, "take: residuals must be a sequence");
  if (found == NULL) {
    return NULL;
  }
  Py_ssize_t n = PySequence_Fast_GET_SIZE(found);
  double *values = PyMem_Malloc(sizeof(double) * (size_t)(n + 1));
  if (values == NULL) {
    Py_DECREF(found);
    return PyErr_NoMemory();
  }
  for (Py_ssize_t i = 0; i < n && !PyErr_Occurred(); i++) {
    values[i] = item_double(PySequence_Fast_GET_ITEM(found, i));
  }
  Py_DECREF(found);
  if (!PyErr_Occurred()) {
    median_take(m, values, n);
  }
  PyMem_Free(values);
  return PyErr_Occurred() ? NULL : PyFloat_FromDouble(m->sigma);
}

static PyObject *median_take_points(NoiseMedian *m, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t start, count;
  if (nargs != 6 || !read_index(args[4], &start) || !read_index(args[5], &count)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError,
                      "take_points(old_times, old_points, times, points, start, count)");
    }
    return NULL;
  }
  PyObject *old_times = PySequence_Fast(args[0], "old_times must be a sequence");
  PyObject *old_points = old_times ? PySequence_Fast(args[1], "old_points must be a sequence")
                                   : NULL;
  Py_buffer views[2];
  int viewed = 0;
  double *memory = NULL;
  PyObject *result = NULL;
  if (old_points == NULL) {
    goto done;
  }
  Py_ssize_t old = PySequence_Fast_GET_SIZE(old_times), fresh = 0, coordinates = 0;
  if (PySequence_Fast_GET_SIZE(old_points) != old) {
    PyErr_SetString(PyExc_ValueError, "take_points: old_times and old_points differ in length");
    goto done;
  }
  if (args[2] != Py_None || args[3] != Py_None) {
    if (!get_doubles(args[2], &views[0], &fresh, "take_points: times", false)) {
      goto done;
    }
    viewed = 1;
    if (!get_doubles(args[3], &views[1], &coordinates, "take_points: points", false)) {
      goto done;
    }
    viewed = 2;
    if (coordinates != 3 * fresh) {
      PyErr_SetString(PyExc_ValueError, "take_points: points must be (len(times), 3)");
      goto done;
    }
  }
  double *out = NULL;
  memory = window_residuals(old_times, old_points, viewed ? views[0].buf : NULL,
                            viewed ? views[1].buf : NULL, fresh, m->span, start, count,
                            "take_points", &out);
  if (memory == NULL) {
    goto done;
  }
  median_push(m, out, 3 * count);
  result = Py_NewRef(Py_None);
done:
  PyMem_Free(memory);
  release_views(views, viewed);
  Py_XDECREF(old_times);
  Py_XDECREF(old_points);
  return result;
}

/*
 * NoiseMedian.take_run(old_times, old_points, old_breaks, times, points) -> None: the residuals
 * of a run of new samples of one segment (times: contiguous float64 (n,), points (n, 3)) after
 * the stream's newest samples before it (sequences: stamps in s, points in m, whether each
 * starts a segment; its windows reach the newest span - 1): every window of `span` ending at a
 * new sample without a segment's start among its span - 1 newest, of the newest capacity / 3
 * of them only (the older ones' residuals would leave at once), as take_stream after each of
 * them in turn would take them (core.detector.noise.NoiseEstimate.take_points).
 */
static PyObject *median_take_run(NoiseMedian *m, PyObject *const *args, Py_ssize_t nargs)
{
  if (nargs != 5) {
    PyErr_SetString(PyExc_TypeError,
                    "take_run(old_times, old_points, old_breaks, times, points)");
    return NULL;
  }
  Py_ssize_t reach = m->span - 1, old_count = PyObject_Length(args[0]);
  Py_ssize_t fresh = PyObject_Length(args[3]);
  PyObject *breaks = PySequence_Fast(args[2], "take_run: old_breaks must be a sequence");
  if (old_count < 0 || fresh < 0 || breaks == NULL) {
    Py_XDECREF(breaks);
    return NULL;
  }
  if (PySequence_Fast_GET_SIZE(breaks) != old_count) {
    Py_DECREF(breaks);
    PyErr_SetString(PyExc_ValueError, "take_run: old_times and old_breaks differ in length");
    return NULL;
  }
  Py_ssize_t old = old_count < reach ? old_count : reach; /* the newest old samples used */
  Py_ssize_t last_break = -1; /* among them, from the oldest used */
  for (Py_ssize_t i = old - 1; i >= 0 && last_break < 0; i--) {
    int broken = PyObject_IsTrue(PySequence_Fast_GET_ITEM(breaks, old_count - old + i));
    if (broken < 0) {
      Py_DECREF(breaks);
      return NULL;
    }
    last_break = broken ? i : -1;
  }
  Py_DECREF(breaks);
  /* sample i of all (the old used, then the new) has a residual when i >= reach and none of
   * i - reach + 1 .. i starts a segment: the new ones from the reach-th after the last break */
  Py_ssize_t first = reach - old;
  first = last_break + reach - old > first ? last_break + reach - old : first;
  first = first > 0 ? first : 0;
  if (first >= fresh) {
    Py_RETURN_NONE;
  }
  Py_ssize_t start = old + first - reach; /* the first window's oldest sample, of those used */
  Py_ssize_t count = old + fresh - reach - start, kept = m->capacity / 3;
  if (count > kept) {
    start += count - kept, count = kept;
  }
  PyObject *start_object = PyLong_FromSsize_t(old_count - old + start);
  PyObject *count_object = start_object ? PyLong_FromSsize_t(count) : NULL;
  PyObject *result = NULL;
  if (count_object != NULL) {
    PyObject *const forwarded[6] = {args[0], args[1], args[3], args[4], start_object,
                                    count_object};
    result = median_take_points(m, forwarded, 6);
  }
  Py_XDECREF(start_object);
  Py_XDECREF(count_object);
  return result;
}

/* |x|, and NaN as inf (a bound: no number) */
static inline double magnitude(double x) { return isnan(x) ? INFINITY : fabs(x); }

/* the k-th largest (k >= 1) of x[0..n) (reordered), by Hoare's selection */
static double kth_largest(double *x, Py_ssize_t n, Py_ssize_t k)
{
  Py_ssize_t lo = 0, hi = n - 1, want = k - 1; /* (descending: want is its index) */
  while (lo < hi) {
    double pivot = x[lo + (hi - lo) / 2];
    Py_ssize_t i = lo, j = hi;
    while (i <= j) {
      while (x[i] > pivot) {
        i++;
      }
      while (x[j] < pivot) {
        j--;
      }
      if (i <= j) {
        double swap = x[i];
        x[i++] = x[j];
        x[j--] = swap;
      }
    }
    if (want <= j) {
      hi = j;
    } else if (want >= i) {
      lo = i;
    } else {
      break;
    }
  }
  return x[want];
}

/*
 * NoiseMedian.bounds(times, points, breaks, pre, block, out): for a chunk's samples of a
 * point stream, an upper bound (m) on the estimate after each (core.detector.plans: the far
 * test's allowance for smoothing under tracker_noise auto). times: n float64 (s), points:
 * (n, 3) float64 (m), breaks: n bools (where a segment starts or may start), the stream's kept
 * samples then the chunk's from pre; out: n - pre float64, written per block of `block`
 * samples. The estimate after sample i is scale times the median of its window W_i (the newest
 * residuals up to i, at least max(count, min_count) of them once it is not 0), so at most
 * scale times W_i's ceil(max(count, min_count) / 2)-th largest |residual|, at most that of any
 * superset U: here, for a block, every window of `span` ending at a sample from the one where
 * `capacity` residuals are sure to have come (samples without a break among their span - 1
 * newest give three each) to the block's last, and the kept residuals where that reaches before the
 * chunk. ValueError: other buffers or shapes.
 */
static PyObject *median_bounds(NoiseMedian *m, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t pre, block;
  if (nargs != 6 || !read_index(args[3], &pre) || !read_index(args[4], &block)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "bounds(times, points, breaks, pre, block, out)");
    }
    return NULL;
  }
  Py_buffer views[3], flags;
  Py_ssize_t n = 0, coordinates = 0, written = 0;
  int viewed = 0, flagged = 0;
  double *scratch = NULL, *found = NULL;
  PyObject *result = NULL;
  if (!get_doubles(args[0], &views[0], &n, "bounds: times", false)) {
    goto done;
  }
  viewed = 1;
  if (!get_doubles(args[1], &views[1], &coordinates, "bounds: points", false)) {
    goto done;
  }
  viewed = 2;
  if (!get_doubles(args[5], &views[2], &written, "bounds: out", true)) {
    goto done;
  }
  viewed = 3;
  if (!get_items(args[2], &flags, n, 1, "?", "bounds: breaks", false)) {
    goto done;
  }
  flagged = 1;
  if (coordinates != 3 * n || pre < 0 || pre > n || written != n - pre || block < 1) {
    PyErr_SetString(PyExc_ValueError, "bounds: shapes do not match");
    goto done;
  }
  const double *t = views[0].buf, *p = views[1].buf;
  const bool *breaks = flags.buf;
  double *out = views[2].buf;
  int reach = m->span - 1;                    /* a window's samples before its newest */
  Py_ssize_t first = pre > reach ? pre : reach; /* the first sample with a whole window */
  Py_ssize_t windows = n > first ? n - first : 0;
  found = PyMem_Malloc(sizeof(double) * (size_t)(3 * windows + 1));
  scratch = PyMem_Malloc(sizeof(double) * (size_t)(3 * windows + m->capacity + 1));
  if (found == NULL || scratch == NULL) {
    PyErr_NoMemory();
    goto done;
  }
  for (Py_ssize_t j = first; j < n; j++) {
    difference_rows(t + j - reach, p + 3 * (j - reach), m->span, 1, found + 3 * (j - first));
  }
  Py_ssize_t least = m->count > m->min_count ? m->count : m->min_count;
  Py_ssize_t k = (least + 1) / 2, sure = (m->capacity + 2) / 3;
  for (Py_ssize_t start = pre; start < n; start += block) {
    Py_ssize_t end = start + block < n ? start + block : n;
    /* back from the block's first sample to where `sure` samples give residuals for sure */
    Py_ssize_t from = start, given = 0;
    for (; from >= pre && given < sure; from--) {
      bool gives = from >= reach;
      for (Py_ssize_t b = from - reach + 1; gives && b <= from; b++) {
        gives = !breaks[b];
      }
      given += gives;
    }
    from = given < sure ? pre : from + 1;
    Py_ssize_t count = 0;
    if (given < sure) { /* the kept residuals too */
      for (Py_ssize_t i = 0, slot = m->head; i < m->count; i++) {
        scratch[count++] = magnitude(m->ring[slot]);
        slot = slot + 1 == m->capacity ? 0 : slot + 1;
      }
    }
    for (Py_ssize_t j = from > first ? from : first; j < end; j++) {
      for (int a = 0; a < 3; a++) {
        scratch[count++] = magnitude(found[3 * (j - first) + a]);
      }
    }
    double bound = 0.0;
    if (count >= k) {
      bound = kth_largest(scratch, count, k);
    } else {
      for (Py_ssize_t i = 0; i < count; i++) {
        bound = scratch[i] > bound ? scratch[i] : bound;
      }
    }
    for (Py_ssize_t j = start; j < end; j++) {
      out[j - pre] = m->scale * bound;
    }
  }
  result = Py_NewRef(Py_None);
done:
  PyMem_Free(found);
  PyMem_Free(scratch);
  if (flagged) {
    PyBuffer_Release(&flags);
  }
  release_views(views, viewed);
  return result;
}

/*
 * NoiseMedian.take_stream(times, values, breaks[, last]) -> None: the residuals a point stream's
 * newest sample completes (core.detector.noise.NoiseEstimate.update): the window of its `span`
 * newest samples, none of the span - 1 newest starting a segment (else nothing is taken), each
 * value a point or a bat sample's position (getattr(value, 'position', value)). times, values,
 * breaks: the stream's lists; with `last` (0 <= last < their length), sample last's, as if the
 * lists ended there (NoiseEstimate.update_at). IndexError: last beyond the lists.
 */
static PyObject *median_take_stream(NoiseMedian *m, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t last = -1;
  if ((nargs != 3 && nargs != 4) || !PyList_Check(args[0]) || !PyList_Check(args[1]) ||
      !PyList_Check(args[2]) || (nargs == 4 && !read_index(args[3], &last))) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "take_stream(times, values, breaks[, last]): three "
                                       "lists and an index");
    }
    return NULL;
  }
  PyObject *times = args[0], *values = args[1], *breaks = args[2];
  Py_ssize_t size = PyList_GET_SIZE(times), span = m->span;
  if (PyList_GET_SIZE(values) != size || PyList_GET_SIZE(breaks) != size) {
    Py_RETURN_NONE;
  }
  if (nargs == 4 && (last < 0 || last >= size)) {
    PyErr_SetString(PyExc_IndexError, "take_stream: last beyond the lists");
    return NULL;
  }
  Py_ssize_t n = nargs == 4 ? last + 1 : size; /* the samples up to last, as if the newest */
  if (n < span) {
    Py_RETURN_NONE;
  }
  for (Py_ssize_t i = n - span + 1; i < n; i++) {
    int broken = PyObject_IsTrue(PyList_GET_ITEM(breaks, i));
    if (broken < 0) {
      return NULL;
    }
    if (broken) {
      Py_RETURN_NONE;
    }
  }
  PyObject *points = PyList_New(span);
  if (points == NULL) {
    return NULL;
  }
  for (Py_ssize_t i = 0; i < span; i++) {
    PyObject *value = PyList_GET_ITEM(values, n - span + i);
    PyObject *point = PyTuple_Check(value) ? Py_NewRef(value)
                                           : PyObject_GetAttr(value, position_name);
    if (point == NULL && PyErr_ExceptionMatches(PyExc_AttributeError)) {
      PyErr_Clear(); /* (getattr(value, 'position', value): a point of another type) */
      point = Py_NewRef(value);
    }
    if (point == NULL) {
      Py_DECREF(points);
      return NULL;
    }
    PyList_SET_ITEM(points, i, point);
  }
  PyObject *window = PyList_GetSlice(times, n - span, n);
  double *memory = NULL, *out = NULL;
  if (window != NULL) {
    memory = window_residuals(window, points, NULL, NULL, 0, m->span, 0, 1, "take_stream",
                              &out);
  }
  Py_XDECREF(window);
  Py_DECREF(points);
  if (memory == NULL) {
    return NULL;
  }
  median_push(m, out, 3);
  PyMem_Free(memory);
  Py_RETURN_NONE;
}

static PyObject *median_residuals(NoiseMedian *m, PyObject *Py_UNUSED(ignored))
{
  PyObject *list = PyList_New(m->count);
  for (Py_ssize_t i = 0, slot = m->head; list != NULL && i < m->count; i++) {
    PyObject *x = PyFloat_FromDouble(m->ring[slot]);
    if (x == NULL) {
      Py_CLEAR(list);
      break;
    }
    PyList_SET_ITEM(list, i, x);
    slot = slot + 1 == m->capacity ? 0 : slot + 1;
  }
  return list;
}

static PyMethodDef median_methods[] = {
    {"take", (PyCFunction)median_take_method, METH_O,
     "take(residuals) -> sigma: residuals (m) in order; the estimate (m)."},
    {"take_stream", (PyCFunction)(void (*)(void))median_take_stream, METH_FASTCALL,
     "take_stream(times, values, breaks[, last]) -> None: the residuals a point stream's newest "
     "sample (or sample last) completes."},
    {"take_run", (PyCFunction)(void (*)(void))median_take_run, METH_FASTCALL,
     "take_run(old_times, old_points, old_breaks, times, points) -> None: the residuals of a "
     "run of new samples after the stream's newest, every whole window of span."},
    {"take_points", (PyCFunction)(void (*)(void))median_take_points, METH_FASTCALL,
     "take_points(old_times, old_points, times, points, start, count) -> None: the residuals "
     "of count windows of span from sample start of the old samples then the new arrays."},
    {"bounds", (PyCFunction)(void (*)(void))median_bounds, METH_FASTCALL,
     "bounds(times, points, breaks, pre, block, out): an upper bound (m) on the estimate "
     "after each of a chunk's samples, per block of samples."},
    {"residuals", (PyCFunction)median_residuals, METH_NOARGS,
     "residuals() -> the kept residuals (m), oldest first."},
    {NULL, NULL, 0, NULL},
};

static PyObject *median_sigma(NoiseMedian *m, void *Py_UNUSED(closure))
{
  median_settle(m);
  return PyFloat_FromDouble(m->sigma);
}

static PyGetSetDef median_getset[] = {
    {"sigma", (getter)median_sigma, NULL,
     "The estimate (m, 1 sigma), set from the residuals held when read.", NULL},
    {NULL, NULL, NULL, NULL, NULL},
};

static PyMemberDef median_members[] = {
    {"count", T_PYSSIZET, offsetof(NoiseMedian, count), READONLY, "Residuals kept."},
    {"span", T_INT, offsetof(NoiseMedian, span), READONLY, "Samples of a residual's window."},
    {NULL, 0, 0, 0, NULL},
};

static PyTypeObject NoiseMedianType = {
    PyVarObject_HEAD_INIT(NULL, 0)
    .tp_name = "baseball_collision.core.toi._kernel.NoiseMedian",
    .tp_basicsize = sizeof(NoiseMedian),
    .tp_dealloc = (destructor)median_dealloc,
    .tp_flags = Py_TPFLAGS_DEFAULT,
    .tp_doc = "NoiseMedian(capacity, scale, floor, min_count, rebuild, span=5): tracker_noise "
              "auto's running median estimate (core.detector.noise).",
    .tp_methods = median_methods,
    .tp_members = median_members,
    .tp_getset = median_getset,
    .tp_new = median_new,
};

/*
 * trims(counts, cuts, trim_from, after, lengths): a stream's trims after each step of a chunk's
 * plan (core.detector.plans._trims): with start the stream's first kept sample (0 before the
 * first step), at step j lengths[j] = counts[j] - start, then where that is at least trim_from
 * and cuts[j] > start the stream drops what is before cuts[j] (start = cuts[j]); after[j] =
 * start. counts (the stream's samples after each step), cuts (where each step's trim would cut):
 * contiguous int64 arrays of n; after, lengths: writable ones of n. ValueError: other buffers.
 */
static PyObject *py_trims(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t trim_from;
  if (nargs != 5 || !read_index(args[2], &trim_from)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "trims(counts, cuts, trim_from, after, lengths)");
    }
    return NULL;
  }
  Py_buffer views[4];
  static const int places[4] = {0, 1, 3, 4};
  static const char *const what[4] = {"trims: counts", "trims: cuts", "trims: after",
                                      "trims: lengths"};
  Py_ssize_t n = PyObject_Length(args[0]);
  int held = 0;
  PyObject *result = NULL;
  if (n < 0) {
    return NULL;
  }
  for (; held < 4; held++) {
    if (!get_items(args[places[held]], &views[held], n, sizeof(int64_t), "ql", what[held],
                   held >= 2)) {
      goto done;
    }
  }
  const int64_t *counts = views[0].buf, *cuts = views[1].buf;
  int64_t *after = views[2].buf, *lengths = views[3].buf, start = 0;
  for (Py_ssize_t j = 0; j < n; j++) {
    lengths[j] = counts[j] - start;
    if (lengths[j] >= trim_from && cuts[j] > start) {
      start = cuts[j];
    }
    after[j] = start;
  }
  result = Py_NewRef(Py_None);
done:
  for (int i = 0; i < held; i++) {
    PyBuffer_Release(&views[i]);
  }
  return result;
}

/* ------------------------------------------------------------------------------------------ */
/*
 * c2_margins: core.detector.broadphase.arrays' far test of the c2 model over many union
 * intervals at once (a chunk's plan), the clearance of clearly_apart's two stages per interval.
 * The bounds are those of core.detector.broadphase.c2 (c2_jump_bulge and c2_reach first, then
 * c2_bulge and c2_bat_growth), over the samples a full window could hold: see that module and
 * arrays.apart_margins' docstring.
 */

#define C2_FAR_OFFSET 40 /* broadphase.c2._FAR_OFFSET: the weights' offsets reach 40 before */

typedef struct {          /* the constants of broadphase.c2, as apart_margins passes them */
  double step_ratio;      /* C2_STEP_RATIO */
  double after_one;       /* _AFTER_ONE */
  double after_two;       /* _AFTER_TWO */
  const double *before;   /* C2_JUMP_BEFORE: C2_FAR_OFFSET coefficients */
  const double *weights;  /* _WEIGHT_LIST: offsets -C2_FAR_OFFSET .. 3 */
  double max_angle;       /* core.motion.c2.MAX_CHART_ANGLE (rad) */
} C2Constants;

typedef struct {          /* one stream's samples and what the far test keeps per sample */
  Py_ssize_t n;
  const double *points;   /* the ball's points or the bat's knobs (n x 3) */
  const double *tips;     /* the bat's tips (n x 3), NULL for the ball */
  const double *times;    /* s */
  const bool *closed;     /* n - 1: whether each sample interval is continuous; NULL: all */
  double *steps;          /* n: times[m] - times[m - 1], steps[0] = 0 */
  double *jumps;          /* n + 3: the chord-velocity jumps (the bat's plus its length's) */
  double *lengths;        /* n: the bat's knob-to-tip lengths */
  Py_ssize_t *previous;   /* n: the last segment start (a sample whose step in is not closed)
                             at or before each sample, -1 for none */
  Py_ssize_t *next;       /* n: the first at or after it, n for none */
} C2Track;

/* (a + b) / 2 as numpy's (a + b) * 0.5 rounds it */
static inline Vec v_middle(Vec a, Vec b)
{
  return (Vec){(a.x + b.x) * 0.5, (a.y + b.y) * 0.5, (a.z + b.z) * 0.5};
}

/* numpy.maximum: a NaN in either gives NaN */
static inline double nan_max(double a, double b) { return isnan(a) || a > b ? a : b; }

/* fill a track's steps, jumps, lengths and segment starts (arrays.py's _c2_jump_bulges and
 * _segments, once per stream) */
static void c2_track_fill(C2Track *s)
{
  Py_ssize_t n = s->n;
  const double *p = s->points, *t = s->times;
  for (Py_ssize_t m = 0; m < n; m++) {
    s->steps[m] = m ? t[m] - t[m - 1] : 0.0;
    if (s->tips != NULL) {
      s->lengths[m] = v_norm(v_sub(row3(s->tips, m), row3(p, m)));
    }
  }
  for (Py_ssize_t m = 0; m < n + 3; m++) {
    s->jumps[m] = 0.0;
  }
  for (Py_ssize_t m = 1; m + 1 < n; m++) {
    double h0 = s->steps[m], h1 = s->steps[m + 1], sum = 0.0;
    for (int c = 0; c < 3; c++) {
      double d = (p[3 * (m + 1) + c] - p[3 * m + c]) / h1
                 - (p[3 * m + c] - p[3 * (m - 1) + c]) / h0;
      sum += d * d;
    }
    s->jumps[m] = sqrt(sum);
    if (s->tips != NULL) {
      const double *l = s->lengths;
      s->jumps[m] += fabs((l[m + 1] - l[m]) / h1 - (l[m] - l[m - 1]) / h0);
    }
  }
  Py_ssize_t last = -1;
  for (Py_ssize_t m = 0; m < n; m++) {
    if (m > 0 && s->closed != NULL && !s->closed[m - 1]) {
      last = m;
    }
    s->previous[m] = last;
  }
  last = n;
  for (Py_ssize_t m = n - 1; m >= 0; m--) {
    if (m > 0 && s->closed != NULL && !s->closed[m - 1]) {
      last = m;
    }
    s->next[m] = last;
  }
}

/* the first and last sample a window over interval k may hold (arrays._segments) */
static void c2_segment(const C2Track *s, Py_ssize_t k, bool uneven, double ratio,
                       Py_ssize_t *first, Py_ssize_t *last)
{
  Py_ssize_t n = s->n, before = s->previous[k], after = k + 2 < n ? s->next[k + 2] : n;
  bool cut = before >= 0, stop = after < n;
  *first = cut ? before : 0;
  *last = stop ? after - 1 : n - 1;
  if (uneven) {
    const double *t = s->times;
    double h = t[k + 1] - t[k];
    double step = t[*first] - t[*first > 0 ? *first - 1 : 0];
    cut = cut && (step > ratio * h || h > ratio * step);
    step = t[*last + 1 < n ? *last + 1 : n - 1] - t[*last];
    stop = stop && (step > ratio * h || h > ratio * step);
    *first = cut ? *first : 0;
    *last = stop ? *last : n - 1;
  }
}

/* c2_jump_bulge over interval k of a track (m; inf where the steps are too uneven) */
static double c2_jump_bound(const C2Track *s, Py_ssize_t k, int look_ahead, int size,
                            const C2Constants *c)
{
  Py_ssize_t low, high;
  c2_segment(s, k, true, c->step_ratio, &low, &high);
  Py_ssize_t first = k + 2 - size > low ? k + 2 - size : low;
  Py_ssize_t last = k + 1 + look_ahead;
  last = last < s->n - 1 ? last : s->n - 1;
  last = last < high ? last : high;
  double bound = 0.0, longest = -INFINITY, shortest = INFINITY;
  for (int a = 0; a < size - 2; a++) {
    if (k - a > first) {
      bound += c->before[a] * s->jumps[k - a];
    }
  }
  for (Py_ssize_t m = first + 1; m <= last; m++) {
    longest = longest > s->steps[m] ? longest : s->steps[m];
    shortest = shortest < s->steps[m] ? shortest : s->steps[m];
  }
  if (last - k > 1) {
    bound += c->after_one * s->jumps[k + 1];
  }
  if (last - k > 2) {
    bound += c->after_two * (2.0 * s->jumps[k + 1] + s->jumps[k + 2]);
  }
  return longest > c->step_ratio * shortest ? INFINITY : longest * bound;
}

typedef struct {          /* a full window's samples over interval k (arrays._Windows) */
  Py_ssize_t k, count;
  Py_ssize_t index[C2_FAR_OFFSET + 4];
  double weight[C2_FAR_OFFSET + 4];
  Py_ssize_t from, to;    /* the entries of the samples inside the window: from .. to */
  bool uneven;
} C2Window;

/* whether the steps between a window's entries from .. to are more than ratio apart */
static bool c2_window_uneven(const C2Track *s, const C2Window *w, Py_ssize_t from,
                             Py_ssize_t to, double ratio)
{
  double longest = -INFINITY, shortest = INFINITY;
  for (Py_ssize_t j = from + 1; j <= to; j++) {
    double step = s->steps[w->index[j]];
    longest = longest > step ? longest : step;
    shortest = shortest < step ? shortest : step;
  }
  return longest > ratio * shortest;
}

static void c2_window_of(const C2Track *s, Py_ssize_t k, int look_ahead, int size,
                         const C2Constants *c, C2Window *w)
{
  Py_ssize_t low, high, n = s->n;
  c2_segment(s, k, false, c->step_ratio, &low, &high);
  Py_ssize_t first = k + 2 - size > low ? k + 2 - size : low;
  Py_ssize_t end = k + 1 + look_ahead < high ? k + 1 + look_ahead : high;
  w->k = k;
  w->count = 0;
  w->from = 0;
  w->to = -1;
  for (int o = 2 - size; o <= look_ahead + 1; o++) {
    Py_ssize_t m = k + o;
    bool inside = m >= first && m <= end;
    Py_ssize_t i = m < 0 ? 0 : m > n - 1 ? n - 1 : m;
    if (inside) {
      w->from = m == first ? w->count : w->from;
      w->to = w->count;
    }
    w->index[w->count] = i;
    w->weight[w->count++] = inside ? c->weights[C2_FAR_OFFSET + o] : 0.0;
  }
  w->uneven = c2_window_uneven(s, w, w->from, w->to, c->step_ratio);
}

/* c2_bulge over a window of dim-wide values (values[i * dim ...] for sample i) */
static double c2_window_bulge(const C2Window *w, const double *times, const double *values,
                              int dim)
{
  Py_ssize_t k = w->k;
  double t0 = times[k], h = times[k + 1] - t0, rate[3], bound = 0.0;
  for (int c = 0; c < dim; c++) {
    rate[c] = (values[dim * (k + 1) + c] - values[dim * k + c]) / h;
  }
  for (Py_ssize_t j = 0; j < w->count; j++) {
    if (w->weight[j] == 0.0) {
      continue;
    }
    Py_ssize_t i = w->index[j];
    double dt = times[i] - t0, sum = 0.0;
    for (int c = 0; c < dim; c++) {
      double d = values[dim * i + c] - values[dim * k + c] - rate[c] * dt;
      sum += d * d;
    }
    bound += w->weight[j] * sqrt(sum);
  }
  return bound;
}

/* the unit axis of bat sample i */
static inline Vec c2_axis(const C2Track *s, Py_ssize_t i)
{
  Vec d = v_sub(row3(s->tips, i), row3(s->points, i));
  double l = s->lengths[i];
  return (Vec){d.x / l, d.y / l, d.z / l};
}

/*
 * A lower bound (m) on the distance between the hulls of (b0, b1) and (k0, e0, k1, e1):
 * core.detector.broadphase.scalar.hull_separation, the same operations in its order; -inf
 * where its direction has no length (or is not a number).
 */
static double hull_separation(Vec b0, Vec b1, Vec k0, Vec e0, Vec k1, Vec e1)
{
  Vec c = v_middle(b0, b1), m = v_middle(k0, k1);
  Vec a = v_sub(v_middle(e0, e1), m);
  double along = a.x * a.x + a.y * a.y + a.z * a.z;
  double s = along > 0.0 ? ((c.x - m.x) * a.x + (c.y - m.y) * a.y + (c.z - m.z) * a.z) / along
                         : 0.0;
  s = s < 0.0 ? 0.0 : s > 1.0 ? 1.0 : s;
  Vec n = {c.x - m.x - s * a.x, c.y - m.y - s * a.y, c.z - m.z - s * a.z};
  double length = sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
  if (!(length > 0.0)) {
    return -INFINITY;
  }
  n = (Vec){n.x / length, n.y / length, n.z / length};
  double lowest = fmin(n.x * b0.x + n.y * b0.y + n.z * b0.z, n.x * b1.x + n.y * b1.y + n.z * b1.z);
  double highest = fmax(fmax(n.x * k0.x + n.y * k0.y + n.z * k0.z,
                             n.x * e0.x + n.y * e0.y + n.z * e0.z),
                        fmax(n.x * k1.x + n.y * k1.y + n.z * k1.z,
                             n.x * e1.x + n.y * e1.y + n.z * e1.z));
  return lowest - highest;
}

/* the six points of a hull_separation call (Python entries), read into p; false with a
 * TypeError */
static bool read_hull_points(PyObject *const *args, Vec p[6], const char *name)
{
  for (int i = 0; i < 6; i++) {
    if (!read_vec(args[i], &p[i])) {
      PyErr_Format(PyExc_TypeError, "%s: six points of 3 numbers", name);
      return false;
    }
  }
  return true;
}

/* hull_separation(b0, b1, k0, e0, k1, e1) -> the bound (m) above, from Python */
static PyObject *py_hull_separation(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Vec p[6];
  if (nargs != 6) {
    PyErr_SetString(PyExc_TypeError, "hull_separation(b0, b1, k0, e0, k1, e1)");
    return NULL;
  }
  if (!read_hull_points(args, p, "hull_separation")) {
    return NULL;
  }
  return PyFloat_FromDouble(hull_separation(p[0], p[1], p[2], p[3], p[4], p[5]));
}

/*
 * far_spheres(b0, b1, k0, e0, k1, e1) -> (ball centre, ball radius, bat centre, bat radius,
 * hull): the scalar far test's bounds before any bulge (core.detector.broadphase.scalar
 * .clearly_apart, the same operations in its order): the ball chord's middle and half its
 * math.dist, the mean of the bat's four end points and the largest math.dist of one from it
 * (the first of equals, as max), and hull_separation of the six points. TypeError: not six
 * points of 3 numbers.
 */
static PyObject *py_far_spheres(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Vec p[6];
  if (nargs != 6) {
    PyErr_SetString(PyExc_TypeError, "far_spheres(b0, b1, k0, e0, k1, e1)");
    return NULL;
  }
  if (!read_hull_points(args, p, "far_spheres")) {
    return NULL;
  }
  Vec b0 = p[0], b1 = p[1], k0 = p[2], e0 = p[3], k1 = p[4], e1 = p[5];
  Vec ball_centre = {(b0.x + b1.x) * 0.5, (b0.y + b1.y) * 0.5, (b0.z + b1.z) * 0.5};
  Vec bat_centre = {(k0.x + e0.x + k1.x + e1.x) * 0.25, (k0.y + e0.y + k1.y + e1.y) * 0.25,
                    (k0.z + e0.z + k1.z + e1.z) * 0.25};
  PyObject *ball_tuple = vec_tuple(ball_centre);
  PyObject *bat_tuple = ball_tuple ? vec_tuple(bat_centre) : NULL;
  PyObject *result = NULL;
  if (bat_tuple == NULL) {
    goto done;
  }
  double ball_radius = 0.5 * python_dist(args[0], args[1]);
  double bat_radius = python_dist(args[2], bat_tuple);
  for (int i = 3; i < 6 && !PyErr_Occurred(); i++) {
    double d = python_dist(args[i], bat_tuple);
    if (d > bat_radius) {
      bat_radius = d;
    }
  }
  if (!PyErr_Occurred()) {
    result = Py_BuildValue("OdOdd", ball_tuple, ball_radius, bat_tuple, bat_radius,
                           hull_separation(b0, b1, k0, e0, k1, e1));
  }
done:
  Py_XDECREF(ball_tuple);
  Py_XDECREF(bat_tuple);
  return result;
}

/* the clearance (m) of clearly_apart's second c2 stage over one interval (arrays'
 * _c2_window_margins), the larger of the spheres' and the hulls' (less hull_reach, m: what
 * smoothing may add; inf: no hull), the bat's window cut as its chart cuts it (c2_chart):
 * -inf where a window's steps are too uneven, or not a number */
static double c2_window_clearance(const C2Track *ball, const C2Track *bat, Py_ssize_t bk,
                                  Py_ssize_t tk, int look_ahead, int size,
                                  const C2Constants *c, double hull_reach)
{
  C2Window bw, tw;
  c2_window_of(ball, bk, look_ahead, size, c, &bw);
  c2_window_of(bat, tk, look_ahead, size, c, &tw);
  double ball_bulge = c2_window_bulge(&bw, ball->times, ball->points, 3);
  /* the bat's window in its chart: rotation vectors from its direction at tk */
  double turns[3 * (C2_FAR_OFFSET + 4)], lengths[C2_FAR_OFFSET + 4];
  double knobs[3 * (C2_FAR_OFFSET + 4)], times[C2_FAR_OFFSET + 4];
  C2Window local = tw;
  Vec origin = c2_axis(bat, tk);
  Py_ssize_t zero = size - 2, from = tw.from, to = tw.to; /* (zero: the entry of offset 0) */
  for (Py_ssize_t j = 0; j < tw.count; j++) {
    Py_ssize_t i = tw.index[j];
    Vec r = rotation_to(origin, c2_axis(bat, i));
    turns[3 * j] = r.x, turns[3 * j + 1] = r.y, turns[3 * j + 2] = r.z;
    for (int d = 0; d < 3; d++) {
      knobs[3 * j + d] = bat->points[3 * i + d];
    }
    lengths[j] = bat->lengths[i];
    times[j] = bat->times[i];
    local.index[j] = j;
    /* the chart's cut (c2_chart): a sample before tk turned more than its limit from tk's
     * direction starts the window after it, one after tk + 1 ends the window before it */
    if (j >= from && j <= to && sqrt(r.x * r.x + r.y * r.y + r.z * r.z) > c->max_angle) {
      if (j < zero) {
        from = j + 1;
      } else if (j > zero + 1 && to == tw.to) {
        to = j - 1;
      }
    }
  }
  for (Py_ssize_t j = 0; j < tw.count; j++) {
    local.weight[j] = j >= from && j <= to ? tw.weight[j] : 0.0;
  }
  tw.uneven = c2_window_uneven(bat, &tw, from, to, c->step_ratio);
  local.k = zero;
  double knob = c2_window_bulge(&local, times, knobs, 3);
  double turn = c2_window_bulge(&local, times, turns, 3);
  double stretch = c2_window_bulge(&local, times, lengths, 1);
  const double *r1 = turns + 3 * (size - 1); /* (offset 1: the turn onto sample tk + 1) */
  double half_cos = cos(0.5 * sqrt(r1[0] * r1[0] + r1[1] * r1[1] + r1[2] * r1[2]));
  double length0 = bat->lengths[tk], length1 = bat->lengths[tk + 1];
  double growth = knob + stretch + (nan_max(length0, length1) + stretch) * (1.0 - half_cos + turn)
                  + 0.25 * fabs(length1 - length0) * v_norm(v_sub(origin, c2_axis(bat, tk + 1)));
  Vec b0 = row3(ball->points, bk), b1 = row3(ball->points, bk + 1);
  Vec k0 = row3(bat->points, tk), k1 = row3(bat->points, tk + 1);
  Vec e0 = row3(bat->tips, tk), e1 = row3(bat->tips, tk + 1);
  Vec ball_centre = v_middle(b0, b1);
  Vec bat_centre = v_scale((Vec){k0.x + e0.x + k1.x + e1.x, k0.y + e0.y + k1.y + e1.y,
                                 k0.z + e0.z + k1.z + e1.z}, 0.25);
  double bat_radius = nan_max(
      nan_max(v_norm(v_sub(k0, bat_centre)), v_norm(v_sub(e0, bat_centre))),
      nan_max(v_norm(v_sub(k1, bat_centre)), v_norm(v_sub(e1, bat_centre))));
  double second = v_norm(v_sub(ball_centre, bat_centre)) - 0.5 * v_norm(v_sub(b0, b1)) - ball_bulge
                  - bat_radius - growth;
  if (hull_reach < INFINITY) {
    double hull = hull_separation(b0, b1, k0, e0, k1, e1) - hull_reach - ball_bulge - growth;
    second = isnan(second) || hull > second ? hull : second;
  }
  return bw.uneven || tw.uneven || isnan(second) ? -INFINITY : second;
}

/*
 * c2_margins(ball, knob, tip, ball_k, bat_k, ball_times, bat_times, ball_closed, bat_closed,
 *            look_ahead, size, margin, constants, out, hull_reach): out[i] = the c2 far test's
 * clearance (m) of union interval i, between the ball's sample interval ball_k[i] and the bat's
 * bat_k[i]: the first stage's (c2_jump_bulge of the ball, c2_reach of the bat), and where that
 * is not above margin[i] (m) the larger with the second's (c2_bulge, c2_bat_growth around the
 * spheres, and around the hulls less hull_reach[i] (m: what smoothing may add; inf or
 * hull_reach None: no hull); numpy.fmax), each over the samples a full window could hold
 * within its segment (core.detector.broadphase.arrays).
 * ball: (n_ball x 3) float64; knob, tip: (n_bat x 3); ball_k, bat_k: m int64, each in
 * [0, n - 2]; times: s; closed: n - 1 bools (whether each sample interval is continuous) or
 * None; look_ahead 0 .. 2; size 2 .. 42; margin: m float64; constants: C2_STEP_RATIO,
 * _AFTER_ONE, _AFTER_TWO, the 40 of C2_JUMP_BEFORE and the 44 of _WEIGHT_LIST
 * (broadphase.c2), MAX_CHART_ANGLE (core.motion.c2); out: m float64, written; hull_reach: m
 * float64 or None.
 * ValueError: other buffers, shapes or numbers; MemoryError.
 */
static PyObject *py_c2_margins(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t look_ahead, size;
  if (nargs != 15 || !read_index(args[9], &look_ahead) || !read_index(args[10], &size)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError,
                      "c2_margins(ball, knob, tip, ball_k, bat_k, ball_times, bat_times, "
                      "ball_closed, bat_closed, look_ahead, size, margin, constants, out, "
                      "hull_reach)");
    }
    return NULL;
  }
  if (look_ahead < 0 || look_ahead > 2 || size < 2 || size > C2_FAR_OFFSET + 2) {
    PyErr_SetString(PyExc_ValueError, "c2_margins: look_ahead 0 .. 2, size 2 .. 42");
    return NULL;
  }
  enum { BALL, KNOB, TIP, BALL_TIMES, BAT_TIMES, MARGIN, CONSTANTS, OUT, DOUBLES };
  static const int positions[OUT] = {0, 1, 2, 5, 6, 11, 12};
  static const char *const names[OUT] = {
      "c2_margins: ball", "c2_margins: knob", "c2_margins: tip", "c2_margins: ball_times",
      "c2_margins: bat_times", "c2_margins: margin", "c2_margins: constants"};
  Py_buffer views[DOUBLES], indices[2], closed[2], reaches;
  Py_ssize_t counts[DOUBLES];
  int held_indices = 0, held_closed = 0, held_reaches = 0;
  PyObject *result = NULL;
  void *memory = NULL;
  if (!get_views(args, positions, OUT, names, views, counts)) {
    return NULL;
  }
  if (!get_doubles(args[13], &views[OUT], &counts[OUT], "c2_margins: out", true)) {
    release_views(views, OUT);
    return NULL;
  }
  Py_ssize_t nb = counts[BALL_TIMES], nt = counts[BAT_TIMES], m = counts[OUT];
  if (counts[BALL] != 3 * nb || counts[KNOB] != 3 * nt || counts[TIP] != 3 * nt ||
      counts[MARGIN] != m ||
      counts[CONSTANTS] != 3 + C2_FAR_OFFSET + C2_FAR_OFFSET + 4 + 1) {
    PyErr_SetString(PyExc_ValueError, "c2_margins: shapes do not match");
    goto done;
  }
  for (; held_indices < 2; held_indices++) {
    if (!get_items(args[3 + held_indices], &indices[held_indices], m, sizeof(int64_t), "ql",
                   held_indices ? "c2_margins: bat_k" : "c2_margins: ball_k", false)) {
      goto done;
    }
  }
  for (; held_closed < 2; held_closed++) {
    PyObject *o = args[7 + held_closed];
    if (o != Py_None &&
        !get_items(o, &closed[held_closed], (held_closed ? nt : nb) - 1, 1, "?",
                   held_closed ? "c2_margins: bat_closed" : "c2_margins: ball_closed",
                   false)) {
      goto done;
    }
  }
  if (args[14] != Py_None) {
    if (!get_buffer(args[14], &reaches, m, false)) {
      goto done;
    }
    held_reaches = 1;
  }
  const double *hull_reach = held_reaches ? reaches.buf : NULL;
  const int64_t *ball_k = indices[0].buf, *bat_k = indices[1].buf;
  for (Py_ssize_t i = 0; i < m; i++) {
    if (ball_k[i] < 0 || ball_k[i] > nb - 2 || bat_k[i] < 0 || bat_k[i] > nt - 2) {
      PyErr_SetString(PyExc_ValueError, "c2_margins: an interval out of its stream");
      goto done;
    }
  }
  /* per track: steps, jumps (+3), lengths (doubles); previous, next (indices) */
  Py_ssize_t doubles = 2 * nb + 3 * nt + 6, whole = 2 * (nb + nt);
  memory = PyMem_Malloc(doubles * sizeof(double) + whole * sizeof(Py_ssize_t));
  if (memory == NULL) {
    PyErr_NoMemory();
    goto done;
  }
  double *d = memory;
  Py_ssize_t *x = (Py_ssize_t *)(d + doubles);
  C2Track ball = {nb, views[BALL].buf, NULL, views[BALL_TIMES].buf,
                  args[7] == Py_None ? NULL : closed[0].buf, d, d + nb, NULL, x, x + nb};
  d += 2 * nb + 3;
  x += 2 * nb;
  C2Track bat = {nt, views[KNOB].buf, views[TIP].buf, views[BAT_TIMES].buf,
                 args[8] == Py_None ? NULL : closed[1].buf, d, d + nt, d + 2 * nt + 3, x, x + nt};
  const double *k = views[CONSTANTS].buf;
  C2Constants constants = {k[0], k[1], k[2], k + 3, k + 3 + C2_FAR_OFFSET,
                           k[3 + C2_FAR_OFFSET + C2_FAR_OFFSET + 4]};
  const double *margin = views[MARGIN].buf;
  double *out = views[OUT].buf;
  int la = (int)look_ahead, w = (int)size;
  Py_BEGIN_ALLOW_THREADS
  c2_track_fill(&ball);
  c2_track_fill(&bat);
  for (Py_ssize_t i = 0; i < m; i++) {
    Py_ssize_t bk = ball_k[i], tk = bat_k[i];
    double quick = c2_jump_bound(&ball, bk, la, w, &constants);
    double bulge = c2_jump_bound(&bat, tk, la, w, &constants);
    Vec b0 = row3(ball.points, bk), b1 = row3(ball.points, bk + 1);
    Vec k0 = row3(bat.points, tk), k1 = row3(bat.points, tk + 1);
    double reach = 0.5 * v_norm(v_sub(k0, k1)) + bulge
                   + nan_max(bat.lengths[tk], bat.lengths[tk + 1]);
    double first = v_norm(v_sub(v_middle(b0, b1), v_middle(k0, k1))) -
                   0.5 * v_norm(v_sub(b0, b1)) - quick - reach;
    if (!(first > margin[i])) {
      double second = c2_window_clearance(&ball, &bat, bk, tk, la, w, &constants,
                                          hull_reach ? hull_reach[i] : INFINITY);
      first = isnan(first) || second > first ? second : first; /* numpy.fmax */
    }
    out[i] = first;
  }
  Py_END_ALLOW_THREADS
  result = Py_NewRef(Py_None);
done:
  PyMem_Free(memory);
  if (held_reaches) {
    PyBuffer_Release(&reaches);
  }
  for (int i = 0; i < held_closed; i++) {
    if (args[7 + i] != Py_None) {
      PyBuffer_Release(&closed[i]);
    }
  }
  for (int i = 0; i < held_indices; i++) {
    PyBuffer_Release(&indices[i]);
  }
  release_views(views, DOUBLES);
  return result;
}


/*
 * departure_reaches(points, times, k, closed, out): out[i] = core.detector.departure's
 * departure_reach over interval k[i] of a stream (m): the closing sample's distance from the
 * parabola through samples k - 2, k - 1, k plus that parabola's bulge from its chord over the
 * interval (its acceleration times h^2 / 8); inf where that is not a finite number; 0 before
 * the third sample (k < 2) and, with closed (n - 1 bools, or None), where samples k - 2 to
 * k + 1 are not one continuous run. points: (n x 3) float64; times: n (s); k: m int64, at most
 * n - 2 where 2 or more; out: m float64, written. ValueError: other buffers or shapes.
 */
static PyObject *py_departure_reaches(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  if (nargs != 5) {
    PyErr_SetString(PyExc_TypeError, "departure_reaches(points, times, k, closed, out)");
    return NULL;
  }
  Py_buffer points, times, out, index, closed;
  Py_ssize_t count, n, m;
  PyObject *result = NULL;
  if (!get_doubles(args[0], &points, &count, "departure_reaches: points", false)) {
    return NULL;
  }
  if (!get_doubles(args[1], &times, &n, "departure_reaches: times", false)) {
    PyBuffer_Release(&points);
    return NULL;
  }
  if (!get_doubles(args[4], &out, &m, "departure_reaches: out", true)) {
    PyBuffer_Release(&times);
    PyBuffer_Release(&points);
    return NULL;
  }
  bool have_index = false, have_closed = false;
  if (count != 3 * n) {
    PyErr_SetString(PyExc_ValueError, "departure_reaches: points and times do not match");
    goto done;
  }
  if (!(have_index = get_items(args[2], &index, m, sizeof(int64_t), "ql",
                               "departure_reaches: k", false))) {
    goto done;
  }
  if (args[3] != Py_None &&
      !(have_closed = get_items(args[3], &closed, n > 0 ? n - 1 : 0, 1, "?",
                                "departure_reaches: closed", false))) {
    goto done;
  }
  const int64_t *k = index.buf;
  const bool *continuous = have_closed ? closed.buf : NULL;
  const double *p = points.buf, *t = times.buf;
  double *reach = out.buf;
  for (Py_ssize_t i = 0; i < m; i++) {
    if (k[i] >= 2 && k[i] > n - 2) {
      PyErr_SetString(PyExc_ValueError, "departure_reaches: an interval without a sample after it");
      goto done;
    }
  }
  for (Py_ssize_t i = 0; i < m; i++) {
    Py_ssize_t j = (Py_ssize_t)k[i];
    reach[i] = 0.0;
    if (j < 2 || (continuous != NULL &&
                  !(continuous[j - 2] && continuous[j - 1] && continuous[j]))) {
      continue;
    }
    double t0 = t[j - 2], t1 = t[j - 1], t2 = t[j], t3 = t[j + 1];
    double w0 = (t3 - t1) * (t3 - t2) / ((t0 - t1) * (t0 - t2));
    double w1 = (t3 - t0) * (t3 - t2) / ((t1 - t0) * (t1 - t2));
    double w2 = 1.0 - w0 - w1, miss = 0.0, bend = 0.0;
    for (int c = 0; c < 3; c++) {
      double p0 = p[3 * (j - 2) + c], p1 = p[3 * (j - 1) + c], p2 = p[3 * j + c];
      double d = p[3 * (j + 1) + c] - (w0 * p0 + w1 * p1 + w2 * p2);
      double second = 2.0 * ((p2 - p1) / (t2 - t1) - (p1 - p0) / (t1 - t0)) / (t2 - t0);
      miss += d * d;
      bend += second * second;
    }
    double found = sqrt(miss) + sqrt(bend) * ((t3 - t2) * (t3 - t2)) / 8.0;
    reach[i] = isfinite(found) ? found : INFINITY;
  }
  result = Py_NewRef(Py_None);
done:
  if (have_closed) {
    PyBuffer_Release(&closed);
  }
  if (have_index) {
    PyBuffer_Release(&index);
  }
  PyBuffer_Release(&out);
  PyBuffer_Release(&times);
  PyBuffer_Release(&points);
  return result;
}


/* a - b wrapped to int64 as numpy's int64 subtraction wraps (no undefined overflow) */
static inline int64_t wrapped_difference(int64_t a, int64_t b)
{
  return (int64_t)((uint64_t)a - (uint64_t)b);
}

/* little-endian unsigned integers of `bytes` bytes at p (whatever the host's order) */
static inline unsigned long long little_endian(const unsigned char *p, int bytes)
{
  unsigned long long x = 0;
  for (int b = bytes - 1; b >= 0; b--) {
    x = x << 8 | p[b];
  }
  return x;
}

/*
 * decode_group(buffer, starts, members, length, frame_end, offset, floats, cdr, stamps, values,
 *              done) -> how many were read
 * A group of raw stamped messages of one layout (bags.decode's bulk path): message i is
 * buffer[starts[i]:starts[i] + length] (uint8; starts int64). Each whose frame_id field (bytes
 * 12 to frame_end) is the first message's byte for byte, and with `cdr` whose first two bytes
 * are 0 and 1 (little-endian CDR), is read into the chunk's row members[i] (int64): stamps[row]
 * its seconds at byte 4 (int32 with `cdr`, else uint32) times 1e9 plus its nanoseconds at
 * byte 8 (uint32), values[row, :floats] (values (n, 7) float64) the `floats` little-endian
 * float64s at `offset`, done[row] true (bool). ValueError: arrays of other types or sizes, a
 * layout outside the messages or a message outside the buffer; IndexError: a row outside.
 */
static PyObject *py_decode_group(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t length, frame_end, offset, floats;
  int cdr;
  if (nargs != 11 || !read_index(args[3], &length) || !read_index(args[4], &frame_end) ||
      !read_index(args[5], &offset) || !read_index(args[6], &floats) ||
      (cdr = PyObject_IsTrue(args[7])) < 0) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "decode_group(buffer, starts, members, length, "
                                       "frame_end, offset, floats, cdr, stamps, values, done)");
    }
    return NULL;
  }
  Py_buffer views[6];
  int held = 0;
  PyObject *result = NULL;
  if (PyObject_GetBuffer(args[0], &views[0], PyBUF_C_CONTIGUOUS) < 0) {
    goto done;
  }
  held = 1;
  if (PyObject_GetBuffer(args[1], &views[1], PyBUF_FORMAT | PyBUF_C_CONTIGUOUS) < 0) {
    goto done;
  }
  held = 2;
  Py_ssize_t k = views[1].len / 8;
  if (!get_items(args[2], &views[2], k, 8, "lq", "decode_group: members", false)) {
    goto done;
  }
  held = 3;
  if (!get_doubles(args[9], &views[3], &(Py_ssize_t){0}, "decode_group: values", true)) {
    goto done;
  }
  held = 4;
  Py_ssize_t rows = views[3].len / (7 * (Py_ssize_t)sizeof(double));
  if (!get_items(args[8], &views[4], rows, 8, "lq", "decode_group: stamps", true)) {
    goto done;
  }
  held = 5;
  if (!get_items(args[10], &views[5], rows, 1, "?", "decode_group: done", true)) {
    goto done;
  }
  held = 6;
  if (views[1].itemsize != 8 || views[1].format == NULL || strlen(views[1].format) != 1 ||
      strchr("lq", views[1].format[0]) == NULL || views[3].len != rows * 7 * 8 ||
      floats < 0 || floats > 7 || frame_end < 12 || frame_end > length ||
      offset + 8 * floats > length || length < 16) {
    PyErr_SetString(PyExc_ValueError, "decode_group: int64 starts and members, (n, 7) values, "
                                      "a layout within the messages");
    goto done;
  }
  const unsigned char *bytes = views[0].buf;
  const long long *starts = views[1].buf, *members = views[2].buf;
  double *values = views[3].buf;
  long long *stamps = views[4].buf;
  bool *read = views[5].buf;
  for (Py_ssize_t i = 0; i < k; i++) {
    if (starts[i] < 0 || starts[i] + length > views[0].len) {
      PyErr_SetString(PyExc_ValueError, "decode_group: a message outside the buffer");
      goto done;
    }
    if (members[i] < 0 || members[i] >= rows) {
      PyErr_SetString(PyExc_IndexError, "decode_group: a row outside the chunk");
      goto done;
    }
  }
  Py_ssize_t count = 0;
  const unsigned char *first = k ? bytes + starts[0] : NULL;
  for (Py_ssize_t i = 0; i < k; i++) {
    const unsigned char *m = bytes + starts[i];
    if (memcmp(m + 12, first + 12, (size_t)(frame_end - 12)) != 0 ||
        (cdr && (m[0] != 0 || m[1] != 1))) {
      continue;
    }
    unsigned long long seconds = little_endian(m + 4, 4);
    long long row = members[i];
    stamps[row] = (cdr ? (long long)(int)(unsigned int)seconds : (long long)seconds) *
                      1000000000LL + (long long)little_endian(m + 8, 4);
    for (Py_ssize_t f = 0; f < floats; f++) {
      unsigned long long word = little_endian(m + offset + 8 * f, 8);
      double x;
      memcpy(&x, &word, sizeof x);
      values[7 * row + f] = x;
    }
    read[row] = true;
    count++;
  }
  result = PyLong_FromSsize_t(count);
done:
  for (int i = 0; i < held; i++) {
    PyBuffer_Release(&views[i]);
  }
  return result;
}

/*
 * plan_rows(roles, stamps, values, origin, codes, offsets, limits, ball_times, ball_stamps,
 *           ball, bat_times, bat_stamps, knobs, tips, positions, quaternions, pre, ok):
 * core.detector.plans' chunk rows as arrays: each ball sample (role codes[0]) and bat pose
 * (codes[1]) of the chunk written after its stream's pre[0] and pre[1] kept rows, in order:
 * its time (stamp - origin) * 1e-9 (s), its stamp, the ball's point, the pose's position, its
 * quaternion made unit and the knob and tip at offsets (knob, tip: body frame, m) as
 * geometry.pose_point places them (the per-sample path's operations in its order, so the same
 * bits); and ok[i]: whether sample i passes the value checks with room to spare (a finite
 * point; a pose's quaternion finite and its length within limits[0] of 1, its position not the
 * origin) and its stamp is after 0 and at most limits[1] ns after the origin. roles: n int8;
 * stamps: n int64; values: (n x 7) float64; the outputs contiguous, written: float64 times,
 * int64 stamps, (rows x 3) points, (rows x 4) quaternions, n bools. ValueError: other buffers,
 * or outputs that do not hold the chunk's samples after pre.
 */
static PyObject *py_plan_rows(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  long long origin, far_ahead;
  Py_ssize_t codes[2], pre[2];
  Vec offsets[2];
  double tolerance;
  if (nargs != 18 || !PyTuple_Check(args[4]) || PyTuple_GET_SIZE(args[4]) != 2 ||
      !PyTuple_Check(args[5]) || PyTuple_GET_SIZE(args[5]) != 2 || !PyTuple_Check(args[6]) ||
      PyTuple_GET_SIZE(args[6]) != 2 || !PyTuple_Check(args[16]) ||
      PyTuple_GET_SIZE(args[16]) != 2) {
    PyErr_SetString(PyExc_TypeError,
                    "plan_rows(roles, stamps, values, origin, codes, offsets, limits, "
                    "ball_times, ball_stamps, ball, bat_times, bat_stamps, knobs, tips, "
                    "positions, quaternions, pre, ok)");
    return NULL;
  }
  origin = PyLong_AsLongLong(args[3]);
  far_ahead = PyLong_AsLongLong(PyTuple_GET_ITEM(args[6], 1));
  if (PyErr_Occurred() || !read_index(PyTuple_GET_ITEM(args[4], 0), &codes[0]) ||
      !read_index(PyTuple_GET_ITEM(args[4], 1), &codes[1]) ||
      !read_index(PyTuple_GET_ITEM(args[16], 0), &pre[0]) ||
      !read_index(PyTuple_GET_ITEM(args[16], 1), &pre[1]) ||
      !read_number(PyTuple_GET_ITEM(args[6], 0), &tolerance)) {
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError, "plan_rows: origin, codes, limits or pre not numbers");
    }
    return NULL;
  }
  if (!read_vec(PyTuple_GET_ITEM(args[5], 0), &offsets[0]) ||
      !read_vec(PyTuple_GET_ITEM(args[5], 1), &offsets[1])) {
    PyErr_SetString(PyExc_TypeError, "plan_rows: offsets must be two 3-vectors");
    return NULL;
  }
  /* the float64 outputs, then the values */
  enum { BALL_TIMES, BALL, BAT_TIMES, KNOBS, TIPS, POSITIONS, QUATERNIONS, VALUES, DOUBLES };
  static const int positions[DOUBLES] = {7, 9, 10, 12, 13, 14, 15, 2};
  static const char *const names[DOUBLES] = {
      "plan_rows: ball_times", "plan_rows: ball", "plan_rows: bat_times", "plan_rows: knobs",
      "plan_rows: tips", "plan_rows: positions", "plan_rows: quaternions", "plan_rows: values"};
  Py_buffer views[DOUBLES], roles, stamps, ball_stamps, bat_stamps, ok;
  Py_ssize_t counts[DOUBLES];
  int held = 0, others = 0;
  PyObject *result = NULL;
  for (; held < DOUBLES; held++) {
    if (!get_doubles(args[positions[held]], &views[held], &counts[held], names[held],
                     held != VALUES)) {
      goto done;
    }
  }
  Py_ssize_t n = counts[VALUES] / 7, m_ball = counts[BALL_TIMES], m_bat = counts[BAT_TIMES];
  Py_buffer *buffers[5] = {&roles, &stamps, &ball_stamps, &bat_stamps, &ok};
  static const int places[5] = {0, 1, 8, 11, 17};
  const Py_ssize_t lengths[5] = {n, n, m_ball, m_bat, n}, sizes[5] = {1, 8, 8, 8, 1};
  static const char *const formats[5] = {"b", "ql", "ql", "ql", "?"};
  static const char *const what[5] = {"plan_rows: roles", "plan_rows: stamps",
                                      "plan_rows: ball_stamps", "plan_rows: bat_stamps",
                                      "plan_rows: ok"};
  for (; others < 5; others++) {
    if (!get_items(args[places[others]], buffers[others], lengths[others], sizes[others],
                   formats[others], what[others], others >= 2)) {
      goto done;
    }
  }
  if (counts[VALUES] != 7 * n || counts[BALL] != 3 * m_ball || counts[KNOBS] != 3 * m_bat ||
      counts[TIPS] != 3 * m_bat || counts[POSITIONS] != 3 * m_bat ||
      counts[QUATERNIONS] != 4 * m_bat || pre[0] < 0 || pre[1] < 0) {
    PyErr_SetString(PyExc_ValueError, "plan_rows: shapes do not match");
    goto done;
  }
  const int8_t *role = roles.buf;
  Py_ssize_t balls = 0, bats = 0;
  for (Py_ssize_t i = 0; i < n; i++) {
    balls += role[i] == codes[0];
    bats += role[i] == codes[1];
  }
  if (pre[0] + balls != m_ball || pre[1] + bats != m_bat) {
    PyErr_SetString(PyExc_ValueError, "plan_rows: outputs do not hold the chunk's samples");
    goto done;
  }
  const int64_t *stamp = stamps.buf;
  const double *v = views[VALUES].buf;
  double *ball_time = views[BALL_TIMES].buf, *ball = views[BALL].buf;
  double *bat_time = views[BAT_TIMES].buf, *knob = views[KNOBS].buf, *tip = views[TIPS].buf;
  double *position = views[POSITIONS].buf, *quaternion = views[QUATERNIONS].buf;
  int64_t *ball_stamp = ball_stamps.buf, *bat_stamp = bat_stamps.buf;
  bool *passes = ok.buf;
  Py_ssize_t b = pre[0], t = pre[1];
  for (Py_ssize_t i = 0; i < n; i++, v += 7) {
    bool in_time = stamp[i] > 0 && wrapped_difference(stamp[i], origin) <= far_ahead;
    double time = (double)wrapped_difference(stamp[i], origin) * 1e-9;
    bool point = isfinite(v[0]) && isfinite(v[1]) && isfinite(v[2]);
    if (role[i] == codes[0]) {
      ball_time[b] = time;
      ball_stamp[b] = stamp[i];
      for (int c = 0; c < 3; c++) {
        ball[3 * b + c] = v[c];
      }
      b++;
      passes[i] = point && in_time;
    } else if (role[i] == codes[1]) {
      double magnitude = sqrt(v[3] * v[3] + v[4] * v[4] + v[5] * v[5] + v[6] * v[6]);
      double *q = quaternion + 4 * t;
      for (int c = 0; c < 4; c++) {
        q[c] = v[3 + c] / magnitude;
      }
      Vec p = {v[0], v[1], v[2]};
      Vec k = pose_point(p, q, offsets[0]), e = pose_point(p, q, offsets[1]);
      double *rows[3] = {position + 3 * t, knob + 3 * t, tip + 3 * t};
      const Vec points[3] = {p, k, e};
      for (int r = 0; r < 3; r++) {
        rows[r][0] = points[r].x, rows[r][1] = points[r].y, rows[r][2] = points[r].z;
      }
      bat_time[t] = time;
      bat_stamp[t] = stamp[i];
      t++;
      passes[i] = point && isfinite(v[3]) && isfinite(v[4]) && isfinite(v[5]) &&
                  isfinite(v[6]) && fabs(magnitude - 1.0) < tolerance &&
                  !(v[0] == 0.0 && v[1] == 0.0 && v[2] == 0.0) && in_time;
    } else {
      passes[i] = false;
    }
  }
  result = Py_NewRef(Py_None);
done:
  for (int i = 0; i < others; i++) {
    PyBuffer_Release(buffers[i]);
  }
  release_views(views, held);
  return result;
}

/*
 * order_checks(stamps, times, first, second, pre, limits, ok, gap): core.detector.plans'
 * order checks of a stream's samples after its pre kept ones, each against the sample before
 * as if every sample before it were accepted. ok: its step (ns) is positive, at most the
 * reset (limits[0], ns), under limits[1] (the hold factor) times (1 - limits[4]) times each of
 * the two steps before or (from the fifth sample on) times the median of the (up to) eight
 * steps before (gate.hold_ahead's upper median); its time step at most max_gap (limits[2], s)
 * times (1 - limits[4]); each of its points (first, second: rows x 3, second None for one)
 * moved less than max_speed (limits[3], m/s) times its time step times (1 - limits[4]).
 * gap: its step is positive, at
 * most the reset times (1 - limits[4]), its time step over max_gap times (1 + limits[4]) and
 * its step over the hold factor times (1 + limits[4]) times the step before. stamps: rows
 * int64; times: rows float64 (s); ok, gap: rows - pre bools, written. ValueError: other
 * buffers or shapes, pre below 3.
 */
static PyObject *py_order_checks(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  Py_ssize_t pre;
  double limit[5];
  PyObject *seq = NULL;
  if (nargs != 8 || !read_index(args[4], &pre) ||
      (seq = PySequence_Fast(args[5], "order_checks: limits")) == NULL ||
      PySequence_Fast_GET_SIZE(seq) != 5) {
    Py_XDECREF(seq);
    if (!PyErr_Occurred()) {
      PyErr_SetString(PyExc_TypeError,
                      "order_checks(stamps, times, first, second, pre, limits, ok, gap)");
    }
    return NULL;
  }
  for (int i = 0; i < 5; i++) {
    if (!read_number(PySequence_Fast_GET_ITEM(seq, i), &limit[i])) {
      Py_DECREF(seq);
      PyErr_SetString(PyExc_TypeError, "order_checks: limits must be 5 numbers");
      return NULL;
    }
  }
  Py_DECREF(seq);
  Py_buffer times, first, second, stamps, ok, gap;
  Py_ssize_t rows, count, other;
  PyObject *result = NULL;
  int held = 0;
  Py_buffer *order[6] = {&times, &first, &second, &stamps, &ok, &gap};
  if (!get_doubles(args[1], &times, &rows, "order_checks: times", false)) {
    return NULL;
  }
  held = 1;
  if (!get_doubles(args[2], &first, &count, "order_checks: first", false)) {
    goto done;
  }
  held = 2;
  bool two = args[3] != Py_None;
  if (two && !get_doubles(args[3], &second, &other, "order_checks: second", false)) {
    goto done;
  }
  held = 3;
  if (count != 3 * rows || (two && other != 3 * rows) || pre < 3 || pre > rows) {
    PyErr_SetString(PyExc_ValueError, "order_checks: shapes do not match (or pre below 3)");
    goto done;
  }
  if (!get_items(args[0], &stamps, rows, 8, "ql", "order_checks: stamps", false)) {
    goto done;
  }
  held = 4;
  if (!get_items(args[6], &ok, rows - pre, 1, "?", "order_checks: ok", true)) {
    goto done;
  }
  held = 5;
  if (!get_items(args[7], &gap, rows - pre, 1, "?", "order_checks: gap", true)) {
    goto done;
  }
  held = 6;
  const int64_t *s = stamps.buf;
  const double *t = times.buf, *points[2] = {first.buf, two ? second.buf : NULL};
  bool *in_order = ok.buf, *after_gap = gap.buf;
  double reset = limit[0], hold = limit[1], max_gap = limit[2], max_speed = limit[3];
  double slack = limit[4], factor = hold * (1.0 - slack);
  for (Py_ssize_t k = pre; k < rows; k++) {
    double step = (double)wrapped_difference(s[k], s[k - 1]);
    double step1 = (double)wrapped_difference(s[k - 1], s[k - 2]);
    double step2 = (double)wrapped_difference(s[k - 2], s[k - 3]);
    double dt = t[k] - t[k - 1];
    bool unheld = step < factor * step1 && step < factor * step2;
    if (!unheld && k >= 4) { /* gate.hold_ahead's own rule then: the median of the last eight */
      double recent[8];
      int count = 0;
      for (Py_ssize_t i = k - 1; i >= 1 && i >= k - 8; i--) {
        double value = (double)wrapped_difference(s[i], s[i - 1]);
        int j = count++;
        for (; j > 0 && recent[j - 1] > value; j--) { /* (kept sorted as they come) */
          recent[j] = recent[j - 1];
        }
        recent[j] = value;
      }
      unheld = step < factor * recent[count / 2];
    }
    bool passes = step > 0 && step <= reset && unheld && dt <= max_gap * (1.0 - slack);
    double bound = max_speed * dt * (1.0 - slack);
    for (int p = 0; p < 2 && passes; p++) {
      if (points[p] != NULL) {
        const double *a = points[p] + 3 * (k - 1), *b = points[p] + 3 * k;
        double dx = b[0] - a[0], dy = b[1] - a[1], dz = b[2] - a[2];
        passes = sqrt(dx * dx + dy * dy + dz * dz) < bound;
      }
    }
    in_order[k - pre] = passes;
    after_gap[k - pre] = step > 0 && step <= reset * (1.0 - slack) &&
                         dt > max_gap * (1.0 + slack) && step > hold * (1.0 + slack) * step1;
  }
  result = Py_NewRef(Py_None);
done:
  for (int i = held - 1; i >= 0; i--) {
    if (i != 2 || two) {
      PyBuffer_Release(order[i]);
    }
  }
  return result;
}


/* numpy's order of float64: NaN after every number */
static inline bool sorts_before(double x, double y) { return x < y || (y != y && x == x); }

/*
 * sorted_search(array, keys, right, out): numpy.searchsorted(array, keys, 'right' if right else
 * 'left') into out, for an ascending float64 array (numpy's order: NaN last) and keys mostly
 * ascending: each search starts from the last key's place and gallops on (a key below the
 * last searches from the start), so ascending keys cost a walk, not a binary search each.
 * array: n float64; keys: m float64; out: m int64, written. ValueError: other buffers.
 */
static PyObject *py_sorted_search(PyObject *self, PyObject *const *args, Py_ssize_t nargs)
{
  if (nargs != 4) {
    PyErr_SetString(PyExc_TypeError, "sorted_search(array, keys, right, out)");
    return NULL;
  }
  int right = PyObject_IsTrue(args[2]);
  if (right < 0) {
    return NULL;
  }
  Py_buffer array, keys, out;
  Py_ssize_t n, m;
  if (!get_doubles(args[0], &array, &n, "sorted_search: array", false)) {
    return NULL;
  }
  if (!get_doubles(args[1], &keys, &m, "sorted_search: keys", false)) {
    PyBuffer_Release(&array);
    return NULL;
  }
  PyObject *result = NULL;
  if (!get_items(args[3], &out, m, sizeof(int64_t), "ql", "sorted_search: out", true)) {
    goto done;
  }
  const double *a = array.buf, *key = keys.buf;
  int64_t *place = out.buf;
  Py_ssize_t lo = 0; /* every entry before lo goes before the key (ascending keys) */
  for (Py_ssize_t i = 0; i < m; i++) {
    double x = key[i];
    if (i > 0 && sorts_before(x, key[i - 1])) {
      lo = 0;
    }
    /* the first index whose entry does not go before x: for 'right' an entry equal to x goes
       before it, for 'left' not */
#define GOES_BEFORE(v) (right ? !sorts_before(x, (v)) : sorts_before((v), x))
    Py_ssize_t step = 1, hi = lo;
    while (hi < n && GOES_BEFORE(a[hi])) {
      lo = hi + 1;
      hi = lo + step - 1 < n ? lo + step - 1 : n;
      step *= 2;
    }
    while (lo < hi) {
      Py_ssize_t mid = lo + (hi - lo) / 2;
      if (GOES_BEFORE(a[mid])) {
        lo = mid + 1;
      } else {
        hi = mid;
      }
    }
#undef GOES_BEFORE
    place[i] = lo;
  }
  PyBuffer_Release(&out);
  result = Py_NewRef(Py_None);
done:
  PyBuffer_Release(&keys);
  PyBuffer_Release(&array);
  return result;
}

/* ------------------------------------------------------------------------------------------ */

static PyMethodDef methods[] = {
    {"bind", py_bind, METH_VARARGS,
     "bind(ImpactResult, its field names, (side, knob_end, tip_end)): the result type"},
    {"capsule", (PyCFunction)(void (*)(void))py_capsule, METH_FASTCALL,
     "capsule(b0, b1, e0, e1, s0, s1, ball_radius, bat_radius, dt): ImpactResult, None or "
     "NotImplemented (input to check)"},
    {"profile", (PyCFunction)(void (*)(void))py_profile, METH_FASTCALL,
     "profile(b0, b1, e0, e1, s0, s1, ball_radius, profile, dt): ImpactResult, None or "
     "NotImplemented (input to check)"},
    {"closest_offset", (PyCFunction)(void (*)(void))py_closest_offset, METH_FASTCALL,
     "closest_offset(b0, b1, e0, e1, s0, s1): the ball's offset from the bat's midpoint at "
     "their closest"},
    {"capsule_rows", py_capsule_rows, METH_VARARGS,
     "capsule_rows(b0, b1, e0, e1, s0, s1, ball_radius, bat_radius, dt, out, start, stop): "
     "batch rows, GIL released"},
    {"first_contact", (PyCFunction)(void (*)(void))py_first_contact, METH_FASTCALL,
     "first_contact(ball, bat, t_start, horizon, ball_radius, profile, tolerance, "
     "coarse_step): (t, ImpactResult), None, or NotImplemented (forecasts not finite)"},
    {"forecast", (PyCFunction)(void (*)(void))py_forecast, METH_FASTCALL,
     "forecast(ball or None, bat or None, t): (ball centre, ball velocity, knob, tip, pivot)"},
    {"bat_bounds", (PyCFunction)(void (*)(void))py_bat_bounds, METH_FASTCALL,
     "bat_bounds(bat, ta, tb): (pivot travel bound, turning rate bound, reach)"},
    {"flight_state", (PyCFunction)(void (*)(void))py_flight_state, METH_FASTCALL,
     "flight_state(columns, centre, scale, t): a flight fit's position and rate at t"},
    {"flight_fit", (PyCFunction)(void (*)(void))py_flight_fit, METH_FASTCALL,
     "flight_fit(times, rows, degree): (centre, scale, coefficients, residual sum of squares) of "
     "a ball's flight fit, or NotImplemented (rank deficient)"},
    {"likeliest", (PyCFunction)(void (*)(void))py_likeliest, METH_FASTCALL,
     "likeliest(p, z, variances, bounds, grid, null_eigenvalue): the smoothing weight of "
     "largest marginal likelihood per group of columns (inf: the stiffest; NaN: none noisy)"},
    {"smoothed", (PyCFunction)(void (*)(void))py_smoothed, METH_FASTCALL,
     "smoothed(p, u, z, y, variances, bounds, weights, null_eigenvalue): a window's smoothed "
     "values (a bytearray of n x c doubles)"},
    {"polyfit", (PyCFunction)(void (*)(void))py_polyfit, METH_FASTCALL,
     "polyfit(times, rows, t, degree): (coefficients, span) of a least-squares polynomial in "
     "(time - t) / span, or NotImplemented (rank deficient)"},
    {"ball_forecast", (PyCFunction)(void (*)(void))py_ball_forecast, METH_FASTCALL,
     "ball_forecast(times, points, first, end, t0, degree, gravity, drag, lift_first): the "
     "ballistic forecast's 10 numbers from a fit of the samples [first, end) and the lift of "
     "[lift_first, end), or NotImplemented"},
    {"ballistic", (PyCFunction)(void (*)(void))py_ballistic, METH_FASTCALL,
     "ballistic(t0, position, velocity, gravity, drag): the ballistic forecast's 10 numbers"},
    {"bat_forecast", (PyCFunction)(void (*)(void))py_bat_forecast, METH_FASTCALL,
     "bat_forecast(times, rows, first, end, degree): the extrapolated bat's 21 numbers from a "
     "fit of the samples [first, end) at the newest, or NotImplemented"},
    {"bat_from_rates", (PyCFunction)(void (*)(void))py_bat_from_rates, METH_FASTCALL,
     "bat_from_rates(t0, first, second, knob, tip): the extrapolated bat's 21 numbers"},
    {"least_accelerating", (PyCFunction)(void (*)(void))py_least_accelerating, METH_FASTCALL,
     "least_accelerating(knob, tip): the fraction along knob-tip accelerating least"},
    {"not_a_knot", (PyCFunction)(void (*)(void))py_not_a_knot, METH_FASTCALL,
     "not_a_knot(times, rows, start): the not-a-knot spline's slopes at knots start..n-1, "
     "a tuple per knot (n >= 4)"},
    {"not_a_knot_quintic", (PyCFunction)(void (*)(void))py_not_a_knot_quintic, METH_FASTCALL,
     "not_a_knot_quintic(times, rows, start): the not-a-knot quintic spline's (slopes, second "
     "derivatives) at knots start..n-1, each a tuple per knot (n >= 6)"},
    {"profile_gap", (PyCFunction)(void (*)(void))py_profile_gap, METH_FASTCALL,
     "profile_gap(ball, knob, tip, ball_radius, profile): (gap in m, unit normal from the axis "
     "to the ball, fraction along knob-tip)"},
    {"lowest_gap", (PyCFunction)(void (*)(void))py_lowest_gap, METH_FASTCALL,
     "lowest_gap(ball0, ball1, knob0, knob1, tip0, tip1, ball_radius, profile): where on a "
     "linear sub-step (0-1) the gap is smallest (golden section, 40 steps)"},
    {"polynomial_basis", (PyCFunction)(void (*)(void))py_polynomial_basis, METH_FASTCALL,
     "polynomial_basis(times, count): an orthonormal basis of the polynomials of degree < count "
     "at the stamps, n x count doubles as bytes"},
    {"step_key", py_step_key, METH_O,
     "step_key(times): a window's steps to the nanosecond as bytes, or None"},
    {"not_a_knot_penalty", py_not_a_knot_penalty, METH_O,
     "not_a_knot_penalty(times): the not-a-knot roughness penalty (n x n doubles)"},
    {"beside_null", (PyCFunction)(void (*)(void))py_beside_null, METH_FASTCALL,
     "beside_null(p, u, times, count, null_eigenvalue): a penalty's eigenpairs given their null "
     "space exactly (in place); the largest squared part removed"},
    {"third_jumps", py_third_jumps, METH_O,
     "third_jumps(times): the not-a-knot interpolant's third-derivative jumps at the inner "
     "knots per unit value, (n - 4) x n doubles as bytes (n >= 5)"},
    {"bat_axis", py_bat_axis, METH_O,
     "bat_axis(sample): (unit knob-to-tip direction, length in m)"},
    {"window_bulge", (PyCFunction)(void (*)(void))py_window_bulge, METH_FASTCALL,
     "window_bulge(times, rows, j, weights, offset, column, width): the c2 far test's bulge"},
    {"point_path_init", (PyCFunction)(void (*)(void))py_point_path_init, METH_FASTCALL,
     "point_path_init(path, t0, t1, p0, p1, m0, m1): a PointPath's slots filled"},
    {"c2_path_init", (PyCFunction)(void (*)(void))py_c2_path_init, METH_FASTCALL,
     "c2_path_init(path, point_class, angle_class, t0, t1, sample0, sample1, knob_slopes, "
     "turn_slopes, length_slopes): a C2BatPath's slots filled"},
    {"bat_window_forecast", (PyCFunction)(void (*)(void))py_bat_window_forecast, METH_FASTCALL,
     "bat_window_forecast(times, values, rows, first, end, degree): a bat stream's window's "
     "forecast (21 numbers) with the turn since its first sample, or NotImplemented"},
    {"bat_window_rows", (PyCFunction)(void (*)(void))py_bat_window_rows, METH_FASTCALL,
     "bat_window_rows(values, rows, first, end): the rows bat_window_forecast fits"},
    {"forecast_outcomes", (PyCFunction)(void (*)(void))py_forecast_outcomes, METH_FASTCALL,
     "forecast_outcomes(ball_times, ball_points, bat_times, knobs, tips, quaternions, windows, "
     "t0s, out, gravity, drag, degree, horizon, ball_radius, profile, tolerance, coarse_step): "
     "the predictor's outcome at many frames of arrays (1 found, 0 none, 2 undecided)"},
    {"fill_turns", (PyCFunction)(void (*)(void))py_fill_turns, METH_FASTCALL,
     "fill_turns(values, turns, first_kept, k): a bat stream's cumulative turns up to k"},
    {"turn_between", (PyCFunction)(void (*)(void))py_turn_between, METH_FASTCALL,
     "turn_between(a, b): the bat's swing rotation vector and roll from sample a to b"},
    {"rotate", (PyCFunction)(void (*)(void))py_rotate, METH_FASTCALL,
     "rotate(reference, rotation): reference turned by a rotation vector across it (Rodrigues)"},
    {"recharted", (PyCFunction)(void (*)(void))py_recharted, METH_FASTCALL,
     "recharted(reference, origin, turn, rate, step): a rotation vector and its rate moved from "
     "one chart to another"},
    {"rotation_to", (PyCFunction)(void (*)(void))py_rotation_to, METH_FASTCALL,
     "rotation_to(reference, direction): the rotation vector (rad) turning one onto the other"},
    {"c2_chart", (PyCFunction)(void (*)(void))py_c2_chart, METH_FASTCALL,
     "c2_chart(samples, j, max_angle): (first, rows) of the c2 window's chart: knob, rotation "
     "vector from samples[j]'s direction, length"},
    {"trims", (PyCFunction)(void (*)(void))py_trims, METH_FASTCALL,
     "trims(counts, cuts, trim_from, after, lengths): a stream's trims after each step"},
    {"departure_reaches", (PyCFunction)(void (*)(void))py_departure_reaches, METH_FASTCALL,
     "departure_reaches(points, times, k, closed, out): departure_reach over many intervals"},
    {"decode_group", (PyCFunction)(void (*)(void))py_decode_group, METH_FASTCALL,
     "decode_group(buffer, starts, members, length, frame_end, offset, floats, cdr, stamps, "
     "values, done): a group of stamped messages of one layout read into a chunk's rows"},
    {"plan_rows", (PyCFunction)(void (*)(void))py_plan_rows, METH_FASTCALL,
     "plan_rows(roles, stamps, values, origin, codes, offsets, limits, ball_times, ball_stamps, "
     "ball, bat_times, bat_stamps, knobs, tips, positions, quaternions, pre, ok): a chunk's "
     "rows as a plan's arrays, and its value checks"},
    {"order_checks", (PyCFunction)(void (*)(void))py_order_checks, METH_FASTCALL,
     "order_checks(stamps, times, first, second, pre, limits, ok, gap): a plan's order checks "
     "of a stream's new samples"},
    {"sorted_search", (PyCFunction)(void (*)(void))py_sorted_search, METH_FASTCALL,
     "sorted_search(array, keys, right, out): numpy.searchsorted for keys mostly ascending"},
    {"c2_margins", (PyCFunction)(void (*)(void))py_c2_margins, METH_FASTCALL,
     "c2_margins(ball, knob, tip, ball_k, bat_k, ball_times, bat_times, ball_closed, "
     "bat_closed, look_ahead, size, margin, constants, out, hull_reach): the c2 far test's "
     "clearances"},
    {"reach_back", (PyCFunction)(void (*)(void))py_reach_back, METH_FASTCALL,
     "reach_back(times, breaks, first, stop, max_gap, span, most): a window's first sample, "
     "reached back within its segment, a span and a count"},
    {"c2_window", (PyCFunction)(void (*)(void))py_c2_window, METH_FASTCALL,
     "c2_window(times, breaks, k, max_gap, look_ahead, size): the range of samples a c2 fit of "
     "interval k takes"},
    {"c2_deviation", (PyCFunction)(void (*)(void))py_c2_deviation, METH_FASTCALL,
     "c2_deviation(knob, turn, length, ta, tb): a bound (m) on a c2 bat's axis points' "
     "distance from their chords over [ta, tb]"},
    {"bat_samples", (PyCFunction)(void (*)(void))py_bat_samples, METH_FASTCALL,
     "bat_samples(cls, knob, tip, position, quaternion, first, last): a chunk's bat samples "
     "(rows first .. last - 1 of the arrays) as cls instances of tuples."},
    {"hull_separation", (PyCFunction)(void (*)(void))py_hull_separation, METH_FASTCALL,
     "hull_separation(b0, b1, k0, e0, k1, e1): a lower bound (m) on the distance between the "
     "hulls of (b0, b1) and (k0, e0, k1, e1)"},
    {"far_spheres", (PyCFunction)(void (*)(void))py_far_spheres, METH_FASTCALL,
     "far_spheres(b0, b1, k0, e0, k1, e1): the scalar far test's spheres and hull separation"},
    {"leaves_flight", (PyCFunction)(void (*)(void))py_leaves_flight, METH_FASTCALL,
     "leaves_flight(times, values, breaks, aligned, k, noise, max_gap, rules): the free "
     "flight's parabola over interval k when its closing sample departed from it, or None"},
    {"kept_parabola", (PyCFunction)(void (*)(void))py_kept_parabola, METH_FASTCALL,
     "kept_parabola(times, values, breaks, aligned, k, max_gap): the free flight over interval "
     "k of a point stream, kept per interval in aligned['parabolas'], or None"},
    {"c2_inside", (PyCFunction)(void (*)(void))py_c2_inside, METH_FASTCALL,
     "c2_inside(path, t): a c2 bat path's (knob, tip) at t"},
    {"zone_clear", (PyCFunction)(void (*)(void))py_zone_clear, METH_FASTCALL,
     "zone_clear(ball_path, bat_path, ta, tb, n, ball_radius, profile, floor): whether the ball "
     "stays beyond floor from a c2 bat over [ta, tb] by the near-miss zone's bound"},
    {"bat_growth", (PyCFunction)(void (*)(void))py_bat_growth, METH_FASTCALL,
     "bat_growth(times, rows, i, sample0, sample1, weights, far_offset, ratio): how far the c2 "
     "bat's axis points may leave their chords over a window's interval i, or None"},
    {"c2_jump_bulge", (PyCFunction)(void (*)(void))py_c2_jump_bulge, METH_FASTCALL,
     "c2_jump_bulge(times, values, breaks, steps, jumps, k, look_ahead, size, max_gap, bat, "
     "constants): the c2 far test's bound from its kept per-sample jumps, or None"},
    {"fast_forward_streams", (PyCFunction)(void (*)(void))py_fast_forward_streams,
     METH_FASTCALL,
     "fast_forward_streams(plan, pos, end, ball, bat, walk, stop, noise, sample_class): the "
     "streams' part of a chunk's fast-forward -> (newest stamp, taken by ball, by bat)"},
    {"point_residuals", (PyCFunction)(void (*)(void))py_point_residuals, METH_FASTCALL,
     "point_residuals(times, points, start, count, scale, floor[, span]): the noise "
     "estimate's residuals of count windows of span (5) from start, three each, and whether "
     "each is small"},
    {"quadratic_roots", py_quadratic_roots, METH_VARARGS, "real roots, ascending"},
    {"bracketed_root", py_bracketed_root, METH_VARARGS,
     "bracketed_root(c, order, lo, hi, f_lo): root of the order-th derivative (0 or 1)"},
    {"critical_points", py_critical_points, METH_O, "critical points of a quartic in (0, 1)"},
    {"touch_candidates", py_touch_candidates, METH_VARARGS,
     "touch_candidates(c, slack_scale, slack_poly): contact candidates in [0, 1]"},
    {"quadratic_entry", py_quadratic_entry, METH_VARARGS,
     "quadratic_entry(a, b, c, slack): first contact tau or None"},
    {"cap_quadratics", (PyCFunction)(void (*)(void))py_cap_quadratics, METH_FASTCALL,
     "the end caps' quadratics"},
    {"side_quartic", (PyCFunction)(void (*)(void))py_side_quartic, METH_FASTCALL,
     "the side's quartic, |u|^2 and w.u"},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT,
    .m_name = "_kernel",
    .m_doc = "The compiled exact time-of-impact kernel.",
    .m_size = -1,
    .m_methods = methods,
};

/* interns each of count attribute names into names; false with an exception */
static bool intern_names(PyObject **names, const char *const *attributes, int count)
{
  for (int i = 0; i < count; i++) {
    names[i] = PyUnicode_InternFromString(attributes[i]);
    if (names[i] == NULL) {
      return false;
    }
  }
  return true;
}

PyMODINIT_FUNC PyInit__kernel(void)
{
  PyObject *m = PyModule_Create(&module);
  if (m == NULL) {
    return NULL;
  }
  if (PyType_Ready(&NoiseMedianType) < 0 ||
      PyModule_AddObject(m, "NoiseMedian", Py_NewRef((PyObject *)&NoiseMedianType)) < 0 ||
      PyModule_AddObject(m, "TOUCH_TOLERANCE", PyFloat_FromDouble(TOUCH_TOLERANCE)) < 0 ||
      PyModule_AddObject(m, "DEGENERATE_AXIS", PyFloat_FromDouble(DEGENERATE_AXIS)) < 0 ||
      PyModule_AddObject(m, "ROOT_SLACK", PyFloat_FromDouble(ROOT_SLACK)) < 0 ||
      PyModule_AddObject(m, "LIFT_MIN_SPAN", PyFloat_FromDouble(LIFT_MIN_SPAN)) < 0 ||
      PyModule_AddIntConstant(m, "LIFT_MIN_SAMPLES", LIFT_MIN_SAMPLES) < 0) {
    Py_DECREF(m);
    return NULL;
  }
  PyObject *math = PyImport_ImportModule("math");
  math_dist = math ? PyObject_GetAttrString(math, "dist") : NULL;
  Py_XDECREF(math);
  knob_name = PyUnicode_InternFromString("knob");
  tip_name = PyUnicode_InternFromString("tip");
  quaternion_name = PyUnicode_InternFromString("quaternion");
  position_name = PyUnicode_InternFromString("position");
  static const char *const path_attributes[3] = {"centre", "radius", "bulge"};
  static const char *const c2_path_attributes[3] = {"turn", "length", "reference"};
  double zeros[4] = {0.0, 0.0, 0.0, 0.0};
  parabolas_name = PyUnicode_InternFromString("parabolas");
  zero_turn = float_tuple(zeros, 4);
  if (parabolas_name == NULL || zero_turn == NULL ||
      !intern_names(path_names, path_attributes, 3) ||
      !intern_names(piece_names, piece_attributes, PIECE_NAMES) ||
      !intern_names(c2_path_names, c2_path_attributes, 3) ||
      !intern_names(c2_own_names, c2_own_attributes, C2_OWN_NAMES) ||
      !intern_names(ff_names, ff_attributes, FF_NAMES)) {
    Py_DECREF(m);
    return NULL;
  }
  if (math_dist == NULL || knob_name == NULL || tip_name == NULL || quaternion_name == NULL ||
      position_name == NULL) {
    Py_DECREF(m);
    return NULL;
  }
#ifdef KERNEL_NUMPY_ROWS
  PyObject *numpy = PyImport_ImportModule("numpy");
  ndarray_type = numpy ? PyObject_GetAttrString(numpy, "ndarray") : NULL;
  Py_XDECREF(numpy);
  if (ndarray_type == NULL) {
    Py_DECREF(m);
    return NULL;
  }
#endif
  return m;
}
