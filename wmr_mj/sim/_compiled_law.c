/* The steering law of controllers.computed_torque as MuJoCo's control callback (mjcb_control).
 *
 * wmr_mj.sim.compiled_law installs wmr_mj_control through ctypes; wmr_mj.sim.batch.run_batch then runs
 * whole blocks of closed-loop steps in C (mujoco.batch.Batch.rollout), with no Python per step.
 * The callback acts only on models that carry the numeric "wmr_mj_law" first and
 * "wmr_mj_reference" second (wmr_mj.sim.compiled_law.attach); on any other model it returns at
 * once, so the Python-law engine and every other model of the process are untouched. A single
 * run (wmr_mj.sim.engine) is a batch of one through this callback.
 *
 * The law is ComputedTorque.voltage_scalar / PDController.voltage_scalar, (3.2)-(3.3) of the
 * paper, term for term and in the same order of IEEE operations (no contraction into fused
 * multiply-adds: built with -ffp-contract=off), and the voltage limit and NaN rule of the serial
 * loop it replaced (tests/reference_loop.py); tests/test_compiled_law.py and tests/test_engine.py
 * check the bits.
 *
 * Kind 2, an external law (a plug-in's pure function of floats, compiled by numba.cfunc in
 * wmr_mj.sim.compiled_law): the law numeric names a slot of the table of law functions that Python
 * registered (wmr_mj_register_law), never an address, and carries the law's constants after its
 * LAW_SIZE fields (LAW_NPARAM of them); the callback calls fn(constants, nparam, alpha, alpha',
 * alpha0, alpha0', alpha0'') and applies the voltage limit and records the userdata as for the
 * built-in laws. A value that is not finite (the Python path of a plug-in fails the run on it) is
 * applied as NaN, so that MuJoCo warns (BADCTRL) and the engine re-runs the block with the Python
 * law, which then fails the run at that step as it would have; an unknown slot gives NaN too.
 *
 * A third numeric "wmr_mj_disturbance" (wmr_mj.sim.compiled_law.attach, optional) holds a torque
 * on the steering joint per control step (N m); the callback writes it to qfrc_applied at every
 * physics step, before the law (wmr_mj.sim.signals). Models without it are untouched.
 *
 * A numeric "wmr_mj_sensing" (wmr_mj.sim.compiled_law.attach, optional, after the others) puts the steering
 * sensor (wmr_mj.hardware.sensing.SensingChain) between the plant and the law: its header (SENSE_*), the
 * chain's parameters (wmr_mj.hardware.sensing P_*), then the noise on alpha and on alpha' per control step.
 * The law then reads the measured alpha and alpha'; E and E' stay the true errors. The chain's state lives in
 * userdata after the 9 fields below (its layout: wmr_mj.hardware.sensing S_*), so a block continues where
 * the last one stopped and a state read back carries it. Models without it are untouched.
 *
 * userdata (7 per simulation; 9 and the chain's state with sensing), written at every control step for the statistics and the rows of a
 * single run (wmr_mj.sim.engine):
 *   alpha (rad), E = alpha0 - alpha (rad), E' = alpha0' - alpha' (rad/s), unsaturated law (V),
 *   alpha' (rad/s), applied voltage (V),
 * and at every physics step, where the law names the chassis body (LAW_CHASSIS >= 0):
 *   heading (rad), the chassis's yaw from xquat as the serial loop computed it (math.atan2);
 * with sensing, also the measured alpha (rad) and alpha' (rad/s) the law read.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>

#include <math.h>
#include <string.h>

#include <mujoco/mujoco.h>

/* the numeric "wmr_mj_law": keep in step with wmr_mj/sim/compiled_law.py (LAW_FIELDS) */
enum {
  LAW_KIND,      /* 0: computed torque, 1: PD, 2: external (a registered function) */
  LAW_P,         /* P^, V s^2/rad */
  LAW_KP,        /* K_P, 1/s^2 */
  LAW_KD,        /* K_D, 1/s */
  LAW_C_V,       /* C_V^, V s/rad */
  LAW_F,         /* F^, V (0: no Coulomb term) */
  LAW_K,         /* K^, V */
  LAW_GYRO_V,    /* gyro^ V_A, V s/rad */
  LAW_WIDTH,     /* width of the smoothed sign, rad/s (0: exact sign) */
  LAW_SIGN,      /* 1: sign of alpha', 2: sign of alpha0' */
  LAW_LIMIT,     /* voltage limit, V */
  LAW_SUBSTEPS,  /* physics steps per control step */
  LAW_NSTEP,     /* control steps in the reference */
  LAW_QPOS,      /* qpos address of the steering joint */
  LAW_DOF,       /* dof address of the steering joint */
  LAW_ACTUATOR,  /* the steering motor */
  LAW_CHASSIS,   /* the chassis body, for the heading (-1: no heading) */
  LAW_FUNCTION,  /* kind 2: the slot of the law function (wmr_mj_register_law) */
  LAW_NPARAM,    /* kind 2: the constants that follow the LAW_SIZE fields */
  LAW_SIZE
};

int wmr_mj_law_size(void) { return LAW_SIZE; }

int wmr_mj_mujoco_version(void) { return mjVERSION_HEADER; }

/* the index of the optional disturbance numeric: its presence tells Python this build applies it */
int wmr_mj_disturbance_numeric(void) { return 2; }

/* the sensing numeric's header, then the chain's parameters: keep in step with compiled_law.py (SENSE_FIELDS)
 * and wmr_mj/hardware/sensing.py (P_*, S_*) */
enum { SENSE_MOTOR_QPOS, SENSE_NSTEP, SENSE_HEADER };
enum { P_TICKS_PER_RAD, P_GEAR_RATIO, P_PERIOD, P_FILTER_A, P_FILTER_ONE_MINUS_A, P_DELAY_STEPS,
       P_ENCODER_SIDE, P_ROUNDING, P_VELOCITY, P_ALPHA_NOISE_ON, P_ALPHA_DOT_NOISE_ON, N_PARAMETERS };
enum { S_NEXT_STEP, S_PREVIOUS_ALPHA, S_FILTER, S_RING };
#define SENSE_USERDATA 9 /* the chain's state starts here in userdata */

/* the velocity codes sense() knows (exact, tachometer, difference, filtered, none): a library older than a code
 * the Python chain gives does not match, and the run falls back to the Python law */
enum { N_VELOCITY_CODES = 5 };

int wmr_mj_sensing_layout(void) { return 100000 * N_VELOCITY_CODES + 1000 * SENSE_HEADER + 10 * N_PARAMETERS + S_RING; }

/* SensingChain.step of wmr_mj/hardware/sensing.py, operation for operation (the same bits); the estimate and the
 * delay are the systems of wmr_mj/hardware/estimators.py, whose coefficients (a, 1 - a) the parameters carry
 * (tests/test_estimators.py drives this function against their matrices) */
static void sense(const mjtNum* sp, mjtNum* s, long long k, double alpha, double alpha_dot, double motor,
                  double* alpha_m_out, double* alpha_dot_m_out) {
  const mjtNum* p = sp + SENSE_HEADER;
  long long nstep = (long long)sp[SENSE_NSTEP];
  const mjtNum* alpha_noise = p + N_PARAMETERS;
  const mjtNum* alpha_dot_noise = alpha_noise + nstep;
  long long slots = (long long)p[P_DELAY_STEPS] + 1;
  mjtNum* ring = s + S_RING;
  long long j = 3 * (k % slots);
  ring[j] = alpha;
  ring[j + 1] = alpha_dot;
  ring[j + 2] = motor;
  if (k == 0) { /* before d steps have passed, every slot holds the state at t = 0 */
    for (long long i = 0; i < 3 * slots; i += 3) {
      ring[i] = alpha;
      ring[i + 1] = alpha_dot;
      ring[i + 2] = motor;
    }
  }
  long long r = 3 * ((k + 1) % slots); /* the slot of step k - d */
  int motor_side = p[P_ENCODER_SIDE] == 1.0;
  double theta = motor_side ? ring[r + 2] : ring[r];
  double c = p[P_TICKS_PER_RAD];
  if (c != 0.0) {
    double x = theta * c;
    /* + 0.0: a count of zero ticks is +0, as Python's int 0 (round, math.floor) converts; rint and floor
     * keep the sign of -0.3 or -0.0 and would give -0 (no other value changes: x + 0.0 = x for x != 0) */
    theta = ((p[P_ROUNDING] == 1.0 ? floor(x) : nearbyint(x)) + 0.0) / c;
  }
  double alpha_m = motor_side ? theta / p[P_GEAR_RATIO] : theta;
  if (p[P_ALPHA_NOISE_ON] != 0.0) {
    alpha_m = alpha_m + alpha_noise[k];
  }
  double v;
  if (p[P_VELOCITY] <= 1.0) { /* exact, tachometer */
    v = ring[r + 1];
  } else if (p[P_VELOCITY] == 4.0) { /* none: the law reads the angle only */
    v = NAN;
  } else {
    v = k == 0 ? 0.0 : (alpha_m - s[S_PREVIOUS_ALPHA]) / p[P_PERIOD];
    if (p[P_VELOCITY] == 3.0) {
      v = p[P_FILTER_A] * s[S_FILTER] + p[P_FILTER_ONE_MINUS_A] * v;
      s[S_FILTER] = v;
    }
  }
  if (p[P_ALPHA_DOT_NOISE_ON] != 0.0) {
    v = v + alpha_dot_noise[k];
  }
  s[S_PREVIOUS_ALPHA] = alpha_m;
  s[S_NEXT_STEP] = (double)(k + 1);
  *alpha_m_out = alpha_m;
  *alpha_dot_m_out = v;
}

/* the sensing numeric of the model, or NULL */
static const mjtNum* sensing_of(const mjModel* m, const mjData* d) {
  for (int i = m->nnumeric - 1; i >= 2; i--) {
    if (strcmp(m->names + m->name_numericadr[i], "wmr_mj_sensing") == 0) {
      const mjtNum* sp = m->numeric_data + m->numeric_adr[i];
      long long nstep = (long long)sp[SENSE_NSTEP];
      long long slots = (long long)sp[SENSE_HEADER + P_DELAY_STEPS] + 1;
      if (m->numeric_size[i] != SENSE_HEADER + N_PARAMETERS + 2 * nstep ||
          m->nuserdata < SENSE_USERDATA + S_RING + 3 * slots) {
        return NULL;
      }
      (void)d;
      return sp;
    }
  }
  return NULL;
}

/* kind 2: u = fn(constants, nparam, alpha, alpha', alpha0, alpha0', alpha0'') */
typedef double (*wmr_mj_law_fn)(const double*, int, double, double, double, double, double);
#define WMR_MJ_MAX_LAWS 4096
static wmr_mj_law_fn registered[WMR_MJ_MAX_LAWS];
static int nregistered;

/* the slot of fn (the same slot for the same function), -1 where the table is full; Python calls it
 * under a lock, before building the models that name the slot, and keeps fn alive for the process */
int wmr_mj_register_law(void* fn) {
  for (int i = 0; i < nregistered; i++) {
    if (registered[i] == (wmr_mj_law_fn)fn) {
      return i;
    }
  }
  if (fn == NULL || nregistered == WMR_MJ_MAX_LAWS) {
    return -1;
  }
  registered[nregistered] = (wmr_mj_law_fn)fn;
  return nregistered++;
}

void wmr_mj_control(const mjModel* m, mjData* d) {
  if (m->nnumeric < 2 || m->nuserdata < 7 || m->numeric_size[0] < LAW_SIZE ||
      strcmp(m->names + m->name_numericadr[0], "wmr_mj_law") != 0) {
    return;
  }
  const mjtNum* law = m->numeric_data + m->numeric_adr[0];
  if (law[LAW_NPARAM] < 0.0 || m->numeric_size[0] != LAW_SIZE + (int)law[LAW_NPARAM]) {
    return;
  }
  const mjtNum* reference = m->numeric_data + m->numeric_adr[1];
  int chassis = (int)law[LAW_CHASSIS];
  if (chassis >= 0 && chassis < m->nbody) {
    /* the kinematics of the state this step starts from are current (mj_fwdPosition ran) */
    const mjtNum* q = d->xquat + 4 * chassis;
    d->userdata[6] = atan2(2.0 * (q[0] * q[3] + q[1] * q[2]), 1.0 - 2.0 * (q[2] * q[2] + q[3] * q[3]));
  }
  long long step = llround(d->time / m->opt.timestep);
  long long substeps = (long long)law[LAW_SUBSTEPS];
  if (m->nnumeric >= 3 && substeps >= 1 && step >= 0 &&
      strcmp(m->names + m->name_numericadr[2], "wmr_mj_disturbance") == 0) {
    /* a disturbance torque on the steering joint, N m per control step, written at every physics step */
    long long j = step / substeps;
    if (j < m->numeric_size[2]) {
      d->qfrc_applied[(int)law[LAW_DOF]] = m->numeric_data[m->numeric_adr[2] + j];
    }
  }
  if (substeps < 1 || step < 0 || step % substeps) {
    return;  /* the control of the period's first step holds (zero-order hold) */
  }
  long long k = step / substeps;
  if (k >= (long long)law[LAW_NSTEP] || 3 * k + 2 >= m->numeric_size[1]) {
    return;  /* past the reference: the run is over */
  }
  double alpha = d->qpos[(int)law[LAW_QPOS]];
  double alpha_dot = d->qvel[(int)law[LAW_DOF]];
  double alpha0 = reference[3 * k], alpha0_dot = reference[3 * k + 1], alpha0_ddot = reference[3 * k + 2];
  double true_alpha = alpha, true_alpha_dot = alpha_dot;
  const mjtNum* sensing = m->nnumeric >= 3 ? sensing_of(m, d) : NULL;
  if (sensing != NULL) {
    if (k >= (long long)sensing[SENSE_NSTEP]) {
      return;
    }
    double motor = sensing[SENSE_HEADER + P_GEAR_RATIO] * d->qpos[(int)sensing[SENSE_MOTOR_QPOS]];
    sense(sensing, d->userdata + SENSE_USERDATA, k, true_alpha, true_alpha_dot, motor, &alpha, &alpha_dot);
    d->userdata[7] = alpha;
    d->userdata[8] = alpha_dot;
  }
  double u;
  int external = law[LAW_KIND] == 2.0;
  if (external) {
    int slot = (int)law[LAW_FUNCTION];
    if (slot >= 0 && slot < nregistered && registered[slot] != NULL) {
      u = registered[slot](law + LAW_SIZE, (int)law[LAW_NPARAM], alpha, alpha_dot, alpha0, alpha0_dot, alpha0_ddot);
    } else {
      u = NAN;
    }
  } else if (law[LAW_KIND] == 1.0) {
    u = law[LAW_P] * (law[LAW_KD] * (alpha0_dot - alpha_dot) + law[LAW_KP] * (alpha0 - alpha));
  } else {
    double servo = alpha0_ddot + law[LAW_KD] * (alpha0_dot - alpha_dot) + law[LAW_KP] * (alpha0 - alpha);
    double c = cos(alpha);
    u = law[LAW_P] * servo;
    if (law[LAW_K] != 0.0) {
      u = u + law[LAW_K] * sin(alpha) / (c * c * c);
    }
    if (law[LAW_C_V] != 0.0) {
      u = u + law[LAW_C_V] * alpha_dot;
    }
    if (law[LAW_F] != 0.0) {
      double x = law[LAW_SIGN] == 2.0 ? alpha0_dot : alpha_dot;
      double width = law[LAW_WIDTH], s;
      if (width > 0.0) {
        s = x / sqrt(x * x + width * width);
      } else {
        s = x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0);
      }
      u = u + law[LAW_F] * s;
    }
    if (law[LAW_GYRO_V] != 0.0) {
      u = u + law[LAW_GYRO_V] * alpha_dot / (c * c);
    }
  }
  double limit = law[LAW_LIMIT], applied;
  if (external && !isfinite(u)) {
    applied = NAN;  /* MuJoCo warns (BADCTRL): the engine re-runs the block in Python, which fails there */
  } else if (u != u) {
    applied = 0.0;  /* NaN from a diverged law: apply nothing, as the Python law */
  } else {
    applied = u > limit ? limit : (u < -limit ? -limit : u);
  }
  d->ctrl[(int)law[LAW_ACTUATOR]] = applied;
  d->userdata[0] = true_alpha;
  d->userdata[1] = alpha0 - true_alpha;
  d->userdata[2] = alpha0_dot - true_alpha_dot;
  d->userdata[3] = u;
  d->userdata[4] = true_alpha_dot;
  d->userdata[5] = applied;
}

/* an importable module, so that setuptools builds and ships the library; ctypes finds the symbols */
static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_compiled_law", "The steering law as a MuJoCo control callback (wmr_mj.sim.compiled_law).",
    -1, NULL, NULL, NULL, NULL, NULL};

PyMODINIT_FUNC PyInit__compiled_law(void) { return PyModule_Create(&module); }
