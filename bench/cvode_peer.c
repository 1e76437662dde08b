/* SUNDIALS CVODE as a peer of impact1d (bench/cvode_peer.py builds and runs it).
 *
 * The loop a user of CVODE writes for a frictionless two-body scene under constant forces
 * (input/case3.nml, input/case5.nml): y = (x1, v1, x2, v2), y' = (v1, f1/m1, v2, f2/m2);
 * the four gaps of docs/method.md section 1 are CVODE's root functions (direction -1: a
 * gap closing); at a root, Newton restitution by sequential impulses as docs/method.md
 * section 4 (the most approaching closed contact first, P = -(1 + r) u / (n . M^-1 n)
 * along M^-1 n), then CVodeReInit from the state after the impacts, and on to t_end.
 * Adams with fixed-point iteration, CVODE's choice for a nonstiff problem (no Jacobian):
 * the fastest set-up tried (case 3, rtol 1e-7, measured while writing this: about 83 us a
 * run; Newton iteration with a dense linear solver, Adams or BDF, about 125 us).
 * Nothing guards the accumulation point of case 5 but bounds: the loop stops after
 * STALL_LIMIT events in a row at one instant, after MAX_EVENTS events or MAX_RESTARTS root
 * returns, or when CVode fails, and says which.
 *
 * usage: cvode_peer name=value ...   (m1 m2 f1 f2 x1 v1 x2 v2 x_left r_left x_right
 *        r_right d_min r_min d_max r_max t_end rtol atol: the scene and the tolerances;
 *        batches, runs: timing, runs per batch, 0 for none)
 * Prints one JSON object: the events, the final state, why the loop stopped, CVODE's
 * counters, and the time per run (the mean over a batch of runs, the best and the median
 * of the batches) with the CVODE memory reused (CVodeReInit per run) and made afresh per
 * run (CVodeCreate ... CVodeFree); process start-up and the first run are not timed.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include <cvode/cvode.h>
#include <nvector/nvector_serial.h>
#include <sundials/sundials_config.h>
#include <sunnonlinsol/sunnonlinsol_fixedpoint.h>

#define N_CONTACTS 4
#define MAX_EVENTS 20000
#define STALL_LIMIT 50          /* events in a row without time advancing */
#define MAX_IMPULSES 100        /* sequential impulses at one root */
#define MAX_RESTARTS 200000     /* root returns in one run */

static const char *KIND[N_CONTACTS] = {"left", "right", "slot_min", "slot_max"};
/* Normals n_k on (x1, x2), docs/method.md section 1. */
static const double NORMAL[N_CONTACTS][2] = {{1, 0}, {0, -1}, {-1, 1}, {1, -1}};

typedef struct {
  double m[2], f[2], x0[2], v0[2], x_left, x_right, d_min, d_max, r[N_CONTACTS];
  double t_end, rtol, atol;
} scene_t;

typedef struct {
  int n_events;
  double t[MAX_EVENTS];
  int kind[MAX_EVENTS];
  double final[4], t_stopped;
  const char *stop_reason;
  int cvode_flag;
  long steps, rhs_evals, root_evals, restarts, empty_roots, warnings;
} result_t;

typedef struct {
  SUNContext ctx;
  N_Vector y;
  SUNNonlinearSolver nls;
  void *mem;
} cvode_t;

/* CVODE's warnings in the current run (a root function zero at both ends of the first step
 * after a restart: the state put on the wall by a root return): counted, not printed. */
static long warnings;

static void on_message(int code, const char *module, const char *function, char *msg, void *data) {
  (void)data;
  if (code == CV_WARNING) warnings++;
  else fprintf(stderr, "[%s %s] %s\n", module, function, msg);
}

static int rhs(double t, N_Vector y, N_Vector ydot, void *data) {
  const scene_t *s = data;
  double *u = N_VGetArrayPointer(y), *du = N_VGetArrayPointer(ydot);
  (void)t;
  du[0] = u[1];
  du[1] = s->f[0] / s->m[0];
  du[2] = u[3];
  du[3] = s->f[1] / s->m[1];
  return 0;
}

static void gaps(const scene_t *s, const double *u, double *g) {
  g[0] = u[0] - s->x_left;
  g[1] = s->x_right - u[2];
  g[2] = (u[2] - u[0]) - s->d_min;
  g[3] = s->d_max - (u[2] - u[0]);
}

static int roots(double t, N_Vector y, double *g, void *data) {
  (void)t;
  gaps(data, N_VGetArrayPointer(y), g);
  return 0;
}

/* Sequential impulses at time t on the contacts CVODE found (found[k]) or that are shut
 * (gap <= 0): while one of them approaches (u = n . v < 0), the impulse of the most
 * approaching, each logged as an impact. Returns the number applied. */
static int impacts(const scene_t *s, double t, const int *found, double *u, result_t *res) {
  double g[N_CONTACTS];
  int applied = 0;
  gaps(s, u, g);
  while (applied < MAX_IMPULSES) {
    int worst = -1;
    double u_worst = 0.0;
    for (int k = 0; k < N_CONTACTS; k++) {
      double un = NORMAL[k][0] * u[1] + NORMAL[k][1] * u[3];
      if ((found[k] || g[k] <= 0.0) && un < u_worst) {
        worst = k;
        u_worst = un;
      }
    }
    if (worst < 0) break;
    const double *n = NORMAL[worst];
    double p = -(1.0 + s->r[worst]) * u_worst / (n[0] * n[0] / s->m[0] + n[1] * n[1] / s->m[1]);
    u[1] += n[0] * p / s->m[0];
    u[3] += n[1] * p / s->m[1];
    if (res->n_events < MAX_EVENTS) {
      res->t[res->n_events] = t;
      res->kind[res->n_events] = worst;
    }
    res->n_events++;
    applied++;
  }
  return applied;
}

static void add_counters(void *mem, result_t *res) {
  long n;
  CVodeGetNumSteps(mem, &n);
  res->steps += n;
  CVodeGetNumRhsEvals(mem, &n);
  res->rhs_evals += n;
  CVodeGetNumGEvals(mem, &n);
  res->root_evals += n;
}

/* One run from the scene's initial state to t_end (or to the bound) on CVODE memory that
 * exists already. count: add CVODE's counters to res (not done in the timed runs). */
static void run(const scene_t *s, cvode_t *cv, result_t *res, int count) {
  double *u = N_VGetArrayPointer(cv->y), t = 0.0, t_last_root = -1.0;
  int found[N_CONTACTS], stalled = 0;
  u[0] = s->x0[0]; u[1] = s->v0[0]; u[2] = s->x0[1]; u[3] = s->v0[1];
  res->n_events = 0;
  res->steps = res->rhs_evals = res->root_evals = res->restarts = res->empty_roots = 0;
  warnings = 0;
  res->stop_reason = "t_end reached";
  res->cvode_flag = 0;
  CVodeReInit(cv->mem, 0.0, cv->y);
  CVodeSetStopTime(cv->mem, s->t_end);
  for (;;) {
    int flag = CVode(cv->mem, s->t_end, cv->y, &t, CV_NORMAL);
    if (count) add_counters(cv->mem, res);
    if (flag != CV_ROOT_RETURN) {
      if (flag < 0) {
        res->stop_reason = "CVode failed";
        res->cvode_flag = flag;
      }
      break;
    }
    CVodeGetRootInfo(cv->mem, found);
    if (impacts(s, t, found, u, res) == 0) res->empty_roots++;
    stalled = (t == t_last_root) ? stalled + 1 : 0;
    t_last_root = t;
    if (stalled >= STALL_LIMIT) {
      res->stop_reason = "stalled: events in a row without time advancing";
      break;
    }
    if (res->n_events >= MAX_EVENTS || res->restarts >= MAX_RESTARTS) {
      res->stop_reason = res->n_events >= MAX_EVENTS ? "event limit" : "root-return limit";
      break;
    }
    CVodeReInit(cv->mem, t, cv->y);
    CVodeSetStopTime(cv->mem, s->t_end);
    res->restarts++;
  }
  memcpy(res->final, u, sizeof res->final);
  res->warnings = warnings;
  res->t_stopped = t;
}

static int check(int flag, const char *what) {
  if (flag < 0) {
    fprintf(stderr, "cvode_peer: %s failed with flag %d\n", what, flag);
    exit(2);
  }
  return flag;
}

static void cvode_create(scene_t *s, cvode_t *cv) {
  int directions[N_CONTACTS] = {-1, -1, -1, -1};
  check(SUNContext_Create(NULL, &cv->ctx), "SUNContext_Create");
  cv->y = N_VNew_Serial(4, cv->ctx);
  double *u = N_VGetArrayPointer(cv->y);
  u[0] = s->x0[0]; u[1] = s->v0[0]; u[2] = s->x0[1]; u[3] = s->v0[1];
  cv->mem = CVodeCreate(CV_ADAMS, cv->ctx);
  if (!cv->mem || !cv->y) check(-1, "CVodeCreate");
  check(CVodeInit(cv->mem, rhs, 0.0, cv->y), "CVodeInit");
  check(CVodeSStolerances(cv->mem, s->rtol, s->atol), "CVodeSStolerances");
  check(CVodeSetUserData(cv->mem, s), "CVodeSetUserData");
  check(CVodeSetErrHandlerFn(cv->mem, on_message, NULL), "CVodeSetErrHandlerFn");
  check(CVodeRootInit(cv->mem, N_CONTACTS, roots), "CVodeRootInit");
  check(CVodeSetRootDirection(cv->mem, directions), "CVodeSetRootDirection");
  cv->nls = SUNNonlinSol_FixedPoint(cv->y, 0, cv->ctx);
  check(CVodeSetNonlinearSolver(cv->mem, cv->nls), "CVodeSetNonlinearSolver");
}

static void cvode_free(cvode_t *cv) {
  CVodeFree(&cv->mem);
  SUNNonlinSolFree(cv->nls);
  N_VDestroy(cv->y);
  SUNContext_Free(&cv->ctx);
}

static double now(void) {
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static int compare(const void *a, const void *b) {
  double x = *(const double *)a, y = *(const double *)b;
  return (x > y) - (x < y);
}

/* Seconds per run: the mean over each of `batches` batches of `runs` runs; best[0] the
 * fastest batch, best[1] the median batch. fresh: CVODE's memory made and freed per run. */
static void time_runs(scene_t *s, cvode_t *cv, result_t *res, int batches, int runs, int fresh,
                      double best[2]) {
  double *per_run = malloc(sizeof(double) * (size_t)batches);
  for (int b = 0; b < batches; b++) {
    double start = now();
    for (int i = 0; i < runs; i++) {
      if (fresh) {
        cvode_t own;
        cvode_create(s, &own);
        run(s, &own, res, 0);
        cvode_free(&own);
      } else {
        run(s, cv, res, 0);
      }
    }
    per_run[b] = (now() - start) / runs;
  }
  qsort(per_run, (size_t)batches, sizeof(double), compare);
  best[0] = per_run[0];
  best[1] = per_run[batches / 2];
  free(per_run);
}

static void parse(int argc, char **argv, scene_t *s, int *batches, int *runs) {
  struct { const char *name; double *to; } fields[] = {
    {"m1", &s->m[0]}, {"m2", &s->m[1]}, {"f1", &s->f[0]}, {"f2", &s->f[1]},
    {"x1", &s->x0[0]}, {"v1", &s->v0[0]}, {"x2", &s->x0[1]}, {"v2", &s->v0[1]},
    {"x_left", &s->x_left}, {"r_left", &s->r[0]}, {"x_right", &s->x_right},
    {"r_right", &s->r[1]}, {"d_min", &s->d_min}, {"r_min", &s->r[2]},
    {"d_max", &s->d_max}, {"r_max", &s->r[3]}, {"t_end", &s->t_end},
    {"rtol", &s->rtol}, {"atol", &s->atol}};
  const int n_fields = sizeof fields / sizeof fields[0];
  for (int a = 1; a < argc; a++) {
    char *eq = strchr(argv[a], '='), *end;
    int known = 0;
    if (!eq) { fprintf(stderr, "cvode_peer: expected name=value, got %s\n", argv[a]); exit(1); }
    *eq = '\0';
    double value = strtod(eq + 1, &end);
    if (*end != '\0' || end == eq + 1) {
      fprintf(stderr, "cvode_peer: %s: not a number: %s\n", argv[a], eq + 1);
      exit(1);
    }
    for (int k = 0; k < n_fields; k++)
      if (strcmp(argv[a], fields[k].name) == 0) { *fields[k].to = value; known = 1; }
    if (strcmp(argv[a], "batches") == 0) { *batches = (int)value; known = 1; }
    if (strcmp(argv[a], "runs") == 0) { *runs = (int)value; known = 1; }
    if (!known) { fprintf(stderr, "cvode_peer: unknown name %s\n", argv[a]); exit(1); }
  }
}

static void print_json(const result_t *res, const double reused[2], const double fresh[2],
                       int batches, int runs) {
  int n = res->n_events < MAX_EVENTS ? res->n_events : MAX_EVENTS;
  printf("{\"sundials\": \"%s\", \"stop_reason\": \"%s\", \"cvode_flag\": %d,\n",
         SUNDIALS_VERSION, res->stop_reason, res->cvode_flag);
  printf(" \"t_stopped\": %.17g, \"final\": [%.17g, %.17g, %.17g, %.17g],\n", res->t_stopped,
         res->final[0], res->final[1], res->final[2], res->final[3]);
  printf(" \"steps\": %ld, \"rhs_evals\": %ld, \"root_evals\": %ld, \"restarts\": %ld,"
         " \"empty_roots\": %ld, \"warnings\": %ld,\n", res->steps, res->rhs_evals,
         res->root_evals, res->restarts, res->empty_roots, res->warnings);
  printf(" \"batches\": %d, \"runs\": %d", batches, runs);
  const char *names[4] = {"reused_best_s", "reused_median_s", "fresh_best_s", "fresh_median_s"};
  const double times[4] = {reused[0], reused[1], fresh[0], fresh[1]};
  for (int k = 0; k < 4; k++) {           /* not timed: null (JSON has no NaN) */
    if (isnan(times[k])) printf(", \"%s\": null", names[k]);
    else printf(", \"%s\": %.6g", names[k], times[k]);
  }
  printf(",\n");
  printf(" \"events\": [");
  for (int i = 0; i < n; i++)
    printf("%s[%.17g, \"%s\"]", i ? ", " : "", res->t[i], KIND[res->kind[i]]);
  printf("]}\n");
}

int main(int argc, char **argv) {
  scene_t s = {.m = {1, 1}, .t_end = 1, .rtol = 1e-10, .atol = 1e-13,
               .r = {1, 1, 1, 1}, .d_min = -1e9, .d_max = 1e9, .x_left = -1e9, .x_right = 1e9};
  int batches = 0, runs = 0;
  static result_t res;        /* MAX_EVENTS entries: static, not on the stack */
  double reused[2] = {NAN, NAN}, fresh[2] = {NAN, NAN};
  cvode_t cv;
  parse(argc, argv, &s, &batches, &runs);
  cvode_create(&s, &cv);
  if (batches > 0 && runs > 0) {
    run(&s, &cv, &res, 0);                   /* warm-up: caches, lazy set-up */
    time_runs(&s, &cv, &res, batches, runs, 0, reused);
    time_runs(&s, &cv, &res, batches, runs, 1, fresh);
  }
  run(&s, &cv, &res, 1);                     /* the run reported, with its counters */
  print_json(&res, reused, fresh, batches, runs);
  cvode_free(&cv);
  return 0;
}
