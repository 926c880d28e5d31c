/* C's projection on its desired path, one block of points at a time: the loop of
 * wmr_mj.analysis.path_error._project, which is otherwise a (points x chords) NumPy computation per block.
 *
 * For each point i of the block and each chord k of the window lo:hi it computes, operation for operation
 * as the NumPy code (_Polyline.block_numpy),
 *
 *     rx = x_i - ax_k;  ry = y_i - ay_k
 *     u  = clip((rx dx_k + ry dy_k) / l2_k, 0, 1)       (NaN stays NaN, -0 stays -0, as numpy.clip)
 *     ex = rx - u dx_k;  ey = ry - u dy_k;  dist2 = ex ex + ey ey
 *
 * takes numpy.argmin's answer over k (the first index of the least value, or the first NaN), stops at the
 * first point whose nearest chord is an end of the window (no local minimum: the caller moves the window
 * on), and computes for the points before it the signed distance and arc length with the curvature
 * corrections, in the NumPy code's order of operations. Built with -ffp-contract=off and without fast math
 * (setup.py), so that no product and sum are fused: the same IEEE double operations, the same bits.
 * wmr_mj.analysis.path_error loads it with ctypes (which releases the GIL for the call) and falls back to
 * NumPy where it is not built; tests/test_path_error.py holds the two to the bit.
 */
#include <Python.h>
#include <math.h>
#include <stdint.h>

static double clip01(double u) {
  if (u < 0.0) return 0.0;
  if (u > 1.0) return 1.0;
  return u; /* NaN and -0 pass, as through numpy.clip */
}

static double sign_of(double x) { /* numpy.sign: +0 for either zero, NaN for NaN */
  return x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : (x == 0.0 ? 0.0 : x));
}

/* numpy.argmin over the chords lo:hi of the squared distances from (x, y): the first index of the least
 * value, or of the first NaN. Two passes (the distances into `d2`, then their argmin), so that the compiler
 * can vectorise the first: element-wise, it rounds as the scalar code does. */
static int64_t nearest_chord(double x, double y, const double *ax, const double *ay, const double *dx,
                             const double *dy, const double *l2, int64_t lo, int64_t hi, double *d2) {
  int64_t m = hi - lo;
  const double *ax_ = ax + lo, *ay_ = ay + lo, *dx_ = dx + lo, *dy_ = dy + lo, *l2_ = l2 + lo;
  for (int64_t k = 0; k < m; k++) {
    double rx = x - ax_[k];
    double ry = y - ay_[k];
    double u = clip01((rx * dx_[k] + ry * dy_[k]) / l2_[k]);
    double ex = rx - u * dx_[k];
    double ey = ry - u * dy_[k];
    d2[k] = ex * ex + ey * ey;
  }
  int64_t j = 0;
  double best = d2[0];
  if (best != best) return lo; /* NaN: numpy.argmin returns the first one */
  for (int64_t k = 1; k < m; k++) {
    double v = d2[k];
    if (v != v) return lo + k;
    if (v < best) {
      best = v;
      j = k;
    }
  }
  return lo + j;
}

/* x, y: the block's points (nb); ax, ay, dx, dy, l2, gs, seg_len, kmid: the whole polyline's chords (nseg; gs
 * has nseg + 1 entries); the window is chords lo:hi; d2: scratch of nseg.
 * Writes s and d of the first m points (the return value) to out_s, out_d, and the arc length the next
 * block starts from to *s_next. */
int64_t wmr_mj_project_block(const double *x, const double *y, int64_t nb, const double *ax, const double *ay,
                             const double *dx, const double *dy, const double *l2, const double *gs,
                             const double *seg_len, const double *kmid, int64_t lo, int64_t hi, int64_t nseg,
                             double *d2, double *out_s, double *out_d, double *s_next) {
  for (int64_t i = 0; i < nb; i++) {
    int64_t j = nearest_chord(x[i], y[i], ax, ay, dx, dy, l2, lo, hi, d2);
    double rx = x[i] - ax[j];
    double ry = y[i] - ay[j];
    double u_raw = (rx * dx[j] + ry * dy[j]) / l2[j];
    double u = clip01(u_raw);
    double ex = rx - u * dx[j];
    double ey = ry - u * dy[j];
    double dist2 = ex * ex + ey * ey;
    /* a minimum on the window's edge is no local minimum: the projection moves on past it */
    if ((j == lo && u == 0.0 && lo > 0) || (j == hi - 1 && u == 1.0 && hi < nseg)) {
      *s_next = j == lo ? gs[lo] : gs[hi];
      return i;
    }
    double cross = dx[j] * ry - dy[j] * rx;
    int far = isinf(dist2);
    double d = far ? copysign(INFINITY, cross) : sign_of(cross) * sqrt(dist2);
    d = d + 0.5 * kmid[j] * (seg_len[j] * seg_len[j]) * u * (1.0 - u);
    double scale = far ? -1.0 : 1.0 - kmid[j] * d;
    double u_arc = 0.5 + (u_raw - 0.5) / (scale > 0.0 ? scale : 1.0);
    double uj = scale > 0.0 ? clip01(u_arc) : u;
    out_s[i] = gs[j] + uj * seg_len[j];
    out_d[i] = d;
  }
  *s_next = out_s[nb - 1];
  return nb;
}

/* an importable module, so that setuptools builds and ships the library; ctypes finds the symbol */
static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_nearest_chord", "C's projection on its path, a block at a time (wmr_mj.analysis.path_error).",
    -1, NULL, NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__nearest_chord(void) { return PyModule_Create(&module); }
