/* The default disc–pad's first 0.3 s from rest in SUNDIALS CVODE, for the
 * peer table of BENCHMARKS.md (issue 16). Not part of CI; built and run by
 * bench/cvode_discpad.sh against Debian's libsundials-dev (SUNDIALS 6).
 *
 * Same equations as squeal (MODEL.md §3, defaults of §2; slip in the
 * positive direction, which holds on this window), rtol 1e-8, atol 1e-16 m
 * for positions and 1e-11 m/s for velocities, with root finding on the
 * sliding velocity and the contact force (squeal's two guards in slip; none
 * is reached before 0.3 s). Prints the end state, the counters and the wall
 * time per simulated second (best of `reps` runs).
 *
 * `erk` runs ARKODE's explicit Runge–Kutta stepper instead, with the
 * Fehlberg 13-stage 8(7) pair (the same class of method as DOP853).
 *
 *   usage: cvode_discpad [adams|bdf|erk] [t_end] [reps]
 */
#include <arkode/arkode_erkstep.h>
#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sunlinsol/sunlinsol_dense.h>
#include <sunmatrix/sunmatrix_dense.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

static const double m_d = 1.0, m_p = 0.1;
static const double k_dx = 1.0e9, c_dx = 1.0, k_dy = 8.0e6, c_dy = 1.0;
static const double k_px = 1.7e9, c_px = 0.2, k_py = 4.25e9, c_py = 0.2;
static const double N = 500.0, V = 1.0, alpha = 0.0;
static const double f0 = 0.1, f1 = 1.0 / 15.0, Uc = 50.0 / 3.0;

static double mu(double v) { return f0 * (1.0 - f1 * v * (1.0 - v / (2.0 * Uc))); }

static int rhs(sunrealtype t, N_Vector zv, N_Vector dzv, void *data) {
  (void)t;
  (void)data;
  const double *z = N_VGetArrayPointer(zv);
  double *dz = N_VGetArrayPointer(dzv);
  double f_y = k_py * (z[2] - z[3]) + c_py * (z[6] - z[7]);
  double v = V + z[4] - z[5];
  double f_t = mu(v) * f_y;
  double f_f = alpha * f_t * z[2];
  dz[0] = z[4];
  dz[1] = z[5];
  dz[2] = z[6];
  dz[3] = z[7];
  dz[4] = (-k_dx * z[0] - c_dx * z[4] - f_t) / m_d;
  dz[5] = (-k_px * z[1] - c_px * z[5] + f_t) / m_p;
  dz[6] = (-k_dy * z[2] - c_dy * z[6] - f_y + f_f) / m_d;
  dz[7] = (f_y - N - f_f) / m_p;
  return 0;
}

/* squeal's guards in slip: −v (slip reversal) and −F_y (separation). */
static int guards(sunrealtype t, N_Vector zv, sunrealtype *g, void *data) {
  (void)t;
  (void)data;
  const double *z = N_VGetArrayPointer(zv);
  g[0] = -(V + z[4] - z[5]);
  g[1] = -(k_py * (z[2] - z[3]) + c_py * (z[6] - z[7]));
  return 0;
}

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

int main(int argc, char **argv) {
  int bdf = argc > 1 && strcmp(argv[1], "bdf") == 0;
  int erk = argc > 1 && strcmp(argv[1], "erk") == 0;
  double t_end = argc > 2 ? atof(argv[2]) : 0.3;
  int reps = argc > 3 ? atoi(argv[3]) : 5;
  SUNContext ctx;
  if (SUNContext_Create(NULL, &ctx)) return 1;
  double best = 1e300;
  long nst = 0, nfe = 0, nge = 0, netf = 0, nroots = 0;
  double zend[8];
  for (int r = 0; r < reps; r++) {
    N_Vector z = N_VNew_Serial(8, ctx), atol = N_VNew_Serial(8, ctx);
    for (int i = 0; i < 8; i++) {
      NV_Ith_S(z, i) = 0.0;
      NV_Ith_S(atol, i) = i < 4 ? 1e-16 : 1e-11;
    }
    if (erk) {
      void *ark = ERKStepCreate(rhs, 0.0, z, ctx);
      ERKStepSVtolerances(ark, 1e-8, atol);
      ERKStepSetTableNum(ark, ARKODE_FEHLBERG_13_7_8);
      ERKStepSetMaxNumSteps(ark, 100000000);
      ERKStepRootInit(ark, 2, guards);
      ERKStepSetStopTime(ark, t_end);
      double t = 0.0, t0 = now();
      nroots = 0;
      while (t < t_end) {
        int flag = ERKStepEvolve(ark, t_end, z, &t, ARK_NORMAL);
        if (flag == ARK_ROOT_RETURN) {
          nroots++;
          continue;
        }
        if (flag < 0) {
          fprintf(stderr, "ERKStep failed: %d at t = %g\n", flag, t);
          return 1;
        }
      }
      double wall = now() - t0;
      if (wall < best) best = wall;
      ERKStepGetNumSteps(ark, &nst);
      ERKStepGetNumRhsEvals(ark, &nfe);
      ERKStepGetNumGEvals(ark, &nge);
      ERKStepGetNumErrTestFails(ark, &netf);
      for (int i = 0; i < 8; i++) zend[i] = NV_Ith_S(z, i);
      ERKStepFree(&ark);
      N_VDestroy(z);
      N_VDestroy(atol);
      continue;
    }
    void *mem = CVodeCreate(bdf ? CV_BDF : CV_ADAMS, ctx);
    CVodeInit(mem, rhs, 0.0, z);
    CVodeSVtolerances(mem, 1e-8, atol);
    CVodeSetMaxNumSteps(mem, 100000000);
    CVodeRootInit(mem, 2, guards);
    SUNMatrix A = NULL;
    SUNLinearSolver LS = NULL;
    SUNNonlinearSolver NLS = NULL;
    if (bdf) {
      A = SUNDenseMatrix(8, 8, ctx);
      LS = SUNLinSol_Dense(z, A, ctx);
      CVodeSetLinearSolver(mem, LS, A);
    } else {
      NLS = SUNNonlinSol_FixedPoint(z, 0, ctx);
      CVodeSetNonlinearSolver(mem, NLS);
    }
    CVodeSetStopTime(mem, t_end);
    double t = 0.0, t0 = now();
    nroots = 0;
    while (t < t_end) {
      int flag = CVode(mem, t_end, z, &t, CV_NORMAL);
      if (flag == CV_ROOT_RETURN) {
        nroots++; /* none expected on this window */
        continue;
      }
      if (flag < 0) {
        fprintf(stderr, "CVode failed: %d at t = %g\n", flag, t);
        return 1;
      }
    }
    double wall = now() - t0;
    if (wall < best) best = wall;
    CVodeGetNumSteps(mem, &nst);
    CVodeGetNumRhsEvals(mem, &nfe);
    CVodeGetNumGEvals(mem, &nge);
    CVodeGetNumErrTestFails(mem, &netf);
    for (int i = 0; i < 8; i++) zend[i] = NV_Ith_S(z, i);
    CVodeFree(&mem);
    if (LS) SUNLinSolFree(LS);
    if (A) SUNMatDestroy(A);
    if (NLS) SUNNonlinSolFree(NLS);
    N_VDestroy(z);
    N_VDestroy(atol);
  }
  printf("%s: t_end %g, %ld steps, %ld rhs, %ld guard evaluations, %ld error-test failures, %ld roots\n",
         erk ? "arkode erk fehlberg 13-7-8" : bdf ? "cvode bdf" : "cvode adams", t_end, nst, nfe, nge, netf, nroots);
  printf("wall %.4f s (best of %d) = %.4f s per simulated second\n", best, reps, best / t_end);
  printf("end state:");
  for (int i = 0; i < 8; i++) printf(" %.12e", zend[i]);
  printf("\n");
  SUNContext_Free(&ctx);
  return 0;
}
