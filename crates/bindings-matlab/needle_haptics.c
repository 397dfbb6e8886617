/* needle_haptics.c: the MEX function of needle-haptics over its C API (needle.h,
 * libneedle_capi.a), one source for MATLAB's `mex` and GNU Octave's `mkoctfile --mex`
 * (build_needle_mex.m builds it with either).
 *
 *   [wrench, status] = needle_haptics('wrench', poses)
 *   [wrench, stiffness, status] = needle_haptics('stiffness', poses)
 *   [wrench, status, phase, punctures, velocity, flags] = needle_haptics('insertion', stack, poses [, period_s, time_constant_s])
 *   info = needle_haptics('info')
 *
 * poses: single, n x 5, one pose per row: x_mm, z_mm, theta_x_deg, theta_z_deg, depth_mm
 * (the block frame of docs/architecture.md, section 3). wrench: single n x 6, fx_n, fy_n,
 * fz_n (N), mx_nmm, my_nmm, mz_nmm (N*mm about the hub); status: uint8 n x 1 (the
 * library's bits, NEEDLE_STATUS_* of needle.h: saturation, FE_UNSOLVED, ERROR); stiffness: single n x 18, d wrench/d depth_mm, then d/d x_mm, then d/d z_mm
 * (six components each). The insertion steps every row once from a fresh state
 * (default 1 kHz, 5 ms velocity filter); phase uint16, punctures uint8, velocity single
 * (mm/s), flags uint8 (NEEDLE_INSERTION_* of needle.h: a glitch the step did not
 * integrate, the wrench held; or the wrench scaled down to its bound), n x 1 each. The library's bits: no conversion happens anywhere.
 *
 * Errors (identifiers needle:poses, needle:args, needle:insertion) say which row and
 * column, 1-based as MATLAB counts: "poses(3, 5) (depth_mm) is NaN".
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "mex.h"
#include "needle.h"

static const char *const COLUMNS[5] = {"x_mm", "z_mm", "theta_x_deg", "theta_z_deg", "depth_mm"};

/* The pose array's checks: a real single n x 5 matrix of finite values. */
static const float *check_poses(const mxArray *a, size_t *n_out) {
  size_t n = mxGetM(a), cols = mxGetN(a);
  if (mxGetNumberOfDimensions(a) != 2)
    mexErrMsgIdAndTxt("needle:poses", "poses must be an n x 5 matrix, got %d dimensions", (int)mxGetNumberOfDimensions(a));
  if (cols != 5)
    mexErrMsgIdAndTxt("needle:poses", "poses has %d columns, the pose has 5 (x_mm, z_mm, theta_x_deg, theta_z_deg, depth_mm): column %d is %s",
                      (int)cols, (int)(cols > 5 ? 6 : cols + 1), cols > 5 ? "one too many" : "missing");
  if (mxIsComplex(a)) mexErrMsgIdAndTxt("needle:poses", "poses must be real");
  if (mxIsDouble(a)) {
    /* Name the first value single cannot hold exactly: the library takes single bits. */
    const double *d = mxGetPr(a);
    for (size_t c = 0; c < 5; c++)
      for (size_t r = 0; r < n; r++) {
        double v = d[r + c * n];
        if (!isnan(v) && (double)(float)v != v)
          mexErrMsgIdAndTxt("needle:poses", "poses is double, the library takes single (its own bits): poses(%d, %d) (%s) = %.17g is not a single value (nearest %.9g); single(poses) converts",
                            (int)(r + 1), (int)(c + 1), COLUMNS[c], v, (double)(float)v);
      }
    mexErrMsgIdAndTxt("needle:poses", "poses is double, the library takes single; every value is a single value: single(poses) converts without rounding");
  }
  if (!mxIsSingle(a)) mexErrMsgIdAndTxt("needle:poses", "poses is %s, the library takes single: single(poses) converts", mxGetClassName(a));
  const float *p = (const float *)mxGetData(a);
  /* Row by row, the first non-finite value (the C API's ERROR bit for that row). */
  for (size_t r = 0; r < n; r++)
    for (size_t c = 0; c < 5; c++)
      if (!isfinite(p[r + c * n]))
        mexErrMsgIdAndTxt("needle:poses", "poses(%d, %d) (%s) is %s: every pose value must be finite", (int)(r + 1), (int)(c + 1), COLUMNS[c],
                          isnan(p[r + c * n]) ? "NaN" : (p[r + c * n] > 0 ? "Inf" : "-Inf"));
  *n_out = n;
  return p;
}

static needle_pose_t pose_at(const float *p, size_t n, size_t r) {
  needle_pose_t q = {p[r], p[r + n], p[r + 2 * n], p[r + 3 * n], p[r + 4 * n]};
  return q;
}

static void put_wrench(float *w, size_t n, size_t r, const needle_wrench_t *x) {
  const float v[6] = {x->fx_n, x->fy_n, x->fz_n, x->mx_nmm, x->my_nmm, x->mz_nmm};
  for (int c = 0; c < 6; c++) w[r + (size_t)c * n] = v[c];
}

static mxArray *numeric(size_t n, size_t cols, mxClassID cls) { return mxCreateNumericMatrix(n, cols, cls, mxREAL); }

static void do_wrench(int nlhs, mxArray *plhs[], const mxArray *poses, int stiffness) {
  size_t n;
  const float *p = check_poses(poses, &n);
  mxArray *w = numeric(n, 6, mxSINGLE_CLASS), *k = stiffness ? numeric(n, 18, mxSINGLE_CLASS) : NULL, *s = numeric(n, 1, mxUINT8_CLASS);
  float *wd = (float *)mxGetData(w), *kd = k ? (float *)mxGetData(k) : NULL;
  uint8_t *sd = (uint8_t *)mxGetData(s);
  for (size_t r = 0; r < n; r++) {
    needle_pose_t q = pose_at(p, n, r);
    needle_wrench_t x;
    if (stiffness) {
      needle_stiffness_t st;
      sd[r] = needle_wrench_and_stiffness(&q, &x, &st);
      for (int c = 0; c < 6; c++) {
        kd[r + (size_t)c * n] = st.by_depth[c];
        kd[r + (size_t)(6 + c) * n] = st.by_x[c];
        kd[r + (size_t)(12 + c) * n] = st.by_z[c];
      }
    } else {
      sd[r] = needle_wrench(&q, &x);
    }
    put_wrench(wd, n, r, &x);
  }
  mxArray *outs[3] = {w, stiffness ? k : s, s};
  int count = stiffness ? 3 : 2;
  for (int i = 0; i < count; i++) {
    if (i < nlhs || i == 0) plhs[i] = outs[i];
    else mxDestroyArray(outs[i]);
  }
}

static float scalar_arg(const mxArray *a, const char *what) {
  if (!mxIsNumeric(a) || mxGetNumberOfElements(a) != 1 || mxIsComplex(a)) mexErrMsgIdAndTxt("needle:args", "%s must be a real number", what);
  return (float)mxGetScalar(a);
}

static void do_insertion(int nlhs, mxArray *plhs[], int nrhs, const mxArray *prhs[]) {
  if (nrhs != 3 && nrhs != 5) mexErrMsgIdAndTxt("needle:args", "usage: needle_haptics('insertion', stack, poses [, period_s, time_constant_s])");
  char stack[4096];
  if (!mxIsChar(prhs[1]) || mxGetString(prhs[1], stack, sizeof stack) != 0)
    mexErrMsgIdAndTxt("needle:args", "stack must be a name (char), e.g. 'liver', or a tissue file's path ending in .toml");
  float period_s = nrhs == 5 ? scalar_arg(prhs[3], "period_s") : 0.001f;
  float tau_s = nrhs == 5 ? scalar_arg(prhs[4], "time_constant_s") : 0.005f;
  size_t n;
  const float *p = check_poses(prhs[2], &n);
  needle_insertion_t state;
  memset(&state, 0, sizeof state);
  /* a name ending in .toml is a tissue file, loaded now and checked as the build checks a
   * compiled-in stack (its refusal names FILE:LINE) */
  size_t len = strlen(stack);
  int is_file = len > 5 && strcmp(stack + len - 5, ".toml") == 0;
  char why[1024] = "";
  int32_t rc = is_file ? needle_insertion_init_file(&state, stack, period_s, tau_s, why, sizeof why)
                       : needle_insertion_init(&state, stack, period_s, tau_s);
  if (rc == NEEDLE_E_ARG && is_file) mexErrMsgIdAndTxt("needle:insertion", "%s", why);
  if (rc == NEEDLE_E_ARG) mexErrMsgIdAndTxt("needle:insertion", "no tissue stack '%s' in this build", stack);
  if (rc != NEEDLE_OK) mexErrMsgIdAndTxt("needle:insertion", "period_s must be finite and > 0, time_constant_s finite and >= 0 (code %d)", (int)rc);
  mxArray *outs[6] = {numeric(n, 6, mxSINGLE_CLASS), numeric(n, 1, mxUINT8_CLASS), numeric(n, 1, mxUINT16_CLASS), numeric(n, 1, mxUINT8_CLASS),
                      numeric(n, 1, mxSINGLE_CLASS), numeric(n, 1, mxUINT8_CLASS)};
  float *w = (float *)mxGetData(outs[0]), *v = (float *)mxGetData(outs[4]);
  uint8_t *s = (uint8_t *)mxGetData(outs[1]), *c = (uint8_t *)mxGetData(outs[3]), *f = (uint8_t *)mxGetData(outs[5]);
  uint16_t *ph = (uint16_t *)mxGetData(outs[2]);
  for (size_t r = 0; r < n; r++) {
    needle_pose_t q = pose_at(p, n, r);
    needle_insertion_result_t out;
    if (needle_insertion_step(&state, &q, &out) != NEEDLE_OK) mexErrMsgIdAndTxt("needle:insertion", "needle_insertion_step failed at row %d", (int)(r + 1));
    put_wrench(w, n, r, &out.wrench);
    s[r] = out.status;
    ph[r] = out.phase;
    c[r] = out.punctures;
    v[r] = out.velocity_mm_per_s;
    f[r] = out.flags;
  }
  for (int i = 0; i < 6; i++) {
    if (i < nlhs || i == 0) plhs[i] = outs[i];
    else mxDestroyArray(outs[i]);
  }
}

static void do_info(mxArray *plhs[]) {
  needle_model_info_t m;
  needle_model_info(&m);
  const char *fields[] = {"set", "fe_sha256", "fitted", "x_max_mm", "z_max_mm", "theta_max_deg", "depth_max_mm"};
  mxArray *s = mxCreateStructMatrix(1, 1, 7, fields);
  mxSetField(s, 0, "set", mxCreateString((const char *)m.set));
  mxSetField(s, 0, "fe_sha256", mxCreateString((const char *)m.fe_sha256));
  mxSetField(s, 0, "fitted", mxCreateLogicalScalar(m.fitted));
  mxSetField(s, 0, "x_max_mm", mxCreateDoubleScalar(m.x_max_mm));
  mxSetField(s, 0, "z_max_mm", mxCreateDoubleScalar(m.z_max_mm));
  mxSetField(s, 0, "theta_max_deg", mxCreateDoubleScalar(m.theta_max_deg));
  mxSetField(s, 0, "depth_max_mm", mxCreateDoubleScalar(m.depth_max_mm));
  plhs[0] = s;
}

void mexFunction(int nlhs, mxArray *plhs[], int nrhs, const mxArray *prhs[]) {
  char cmd[16];
  if (nrhs < 1 || !mxIsChar(prhs[0]) || mxGetString(prhs[0], cmd, sizeof cmd) != 0)
    mexErrMsgIdAndTxt("needle:args", "usage: needle_haptics('wrench' | 'stiffness' | 'insertion' | 'info', ...)");
  if (strcmp(cmd, "wrench") == 0 || strcmp(cmd, "stiffness") == 0) {
    if (nrhs != 2) mexErrMsgIdAndTxt("needle:args", "usage: needle_haptics('%s', poses)", cmd);
    do_wrench(nlhs, plhs, prhs[1], cmd[0] == 's');
  } else if (strcmp(cmd, "insertion") == 0) {
    do_insertion(nlhs, plhs, nrhs, prhs);
  } else if (strcmp(cmd, "info") == 0) {
    do_info(plhs);
  } else {
    mexErrMsgIdAndTxt("needle:args", "unknown command '%s': wrench, stiffness, insertion or info", cmd);
  }
}
