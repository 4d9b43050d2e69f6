"""Layouts shared by the transverse drivers: the settings vector and the output columns."""

# Entries of the `settings` vector.
RTOL = 0            # relative tolerance
ATOL = 1            # absolute tolerance (m and m/s), added to ATOL_SCALE's (0 for none)
T_END = 2           # end time (s)
MAX_STEPS = 3       # bound on accepted steps
MAX_STEP = 4        # largest step (s); inf for none
FIRST_STEP = 5      # first step (s); 0 for SciPy's automatic choice
TAIL = 6            # tail window as a fraction of t_end, in (0, 1]
TOL = 7             # settling band / decay threshold, relative
SAMPLE_DT = 8       # time-series sample interval (s); used only when series has columns
WANT_SETTLING = 9   # 1.0: compute settling times; 0.0: skip that work
MIN_STEP = 10       # smallest step (s) before STEP_TOO_SMALL; SciPy's 10 ulps of t if larger
CONTROLLER = 11     # step-size controller: 0.0 SciPy's (step for step as solve_ivp), 1.0 PI
METHOD = 12         # integrator: 0.0 RK45 (Dormand-Prince 5(4)), 1.0 DOP853 (8(5,3))
ATOL_SCALE = 13     # c, 1: absolute tolerances c rtol q_scale (m) and c rtol v_scale (m/s)
                    # from each point's own scales (oscillator.Q_SCALE); 0.0: ATOL alone
BASE = 14           # 1.0: the scene has base excitation (the forcing term and the absolute
                    # acceleration are compiled in: oscillator's `base` switch); 0.0: none
CONSTANT_STIFFNESS = 15  # 1.0: no row has a time-varying stiffness (k1 = g1 = 0 everywhere: a
                    # constant or zero end load), so cos(W t) is compiled out
                    # (oscillator's `parametric` switch); 0.0, the default: rows may have one
SWEPT = 16          # 1.0: the base frequency is swept (kernels.excitation's RATE != 0): the
                    # sweep's outputs (metrics.sweep_metrics) are computed; 0.0: none
BANDS_PER_OCTAVE = 17   # N of the response envelope's 1/N-octave bands (swept scenes)
FIRST_BAND = 18     # the envelope's first band k: centre 1000 x 2^(k/N) Hz (base-2 bands)
STOP_STEADY = 19    # 1.0: a point whose response is steady (or has decayed) ends early, its
                    # tail window moved to the STEADY_PERIODS periods after it was found so
                    # (metrics.steady_period); 0.0, the default: every point runs to t_end
STEADY_PERIODS = 20  # M: the periods the steadiness test spans and the moved tail window holds
STEADY_TOL = 21     # eps: the test's tolerance on the extrema, relative to the amplitude
LOADS = 22          # 1.0: the multi-mode drivers observe the span's loads (the curvatures, the
                    # stretch and the clamp shear: sweep.models.loads); 0.0: they skip them
N_LEVELS = 23       # a random base acceleration (the record kind): how many levels of
                    # |q| (outputs.clearance) have their up-crossings counted, <= MAX_LEVELS
LEVEL_0 = 24        # ... level k (m) at LEVEL_0 + k
MAX_LEVELS = 4
N_SETTINGS = LEVEL_0 + MAX_LEVELS

# Columns of the `reals` output.
AMPLITUDE = 0       # max |q| over the tail window (m)
PEAK = 1            # max |q| over the whole run (m)
SETTLING = 2        # settling time (s) or NaN
PERIOD = 3          # mean time between maxima of q in the tail (s) or NaN
FAILURE_TIME = 4    # time at which a diverged or failed point stopped (s) or NaN
ACCELERATION = 5    # max |q'' + a_b| over the tail window (m/s^2): the absolute midspan
                    # acceleration amplitude under base excitation; NaN without (BASE = 0)
Q_END = 6           # q at the end of the run (m): where a stepped sweep's next point starts;
V_END = 7           # q' there (m/s); both NaN where the point failed
PEAK_FREQUENCY = 8  # swept scenes: the excitation frequency (Hz) when |q| had its largest
                    # extremum; NaN otherwise
STOP_TIME = 9       # with STOP_STEADY: when a point found steady ended (s, before t_end); NaN
                    # for a point that ran to t_end
SPAN_MAX = 10       # multi-mode: max |w(x, t)| over the span and the tail window (m), the
                    # largest deflection anywhere (>= AMPLITUDE); NaN for one mode
CLAMP_BEND = 11     # multi-mode: max |sum phi_n''(e) q_n| over both clamps e and the tail
                    # window (m): the curvature at a clamp times l^2; NaN for one mode
MID_BEND = 12       # multi-mode: max |sum phi_n''(1/2) q_n| over the tail window (m): the
                    # curvature at midspan times l^2; NaN for one mode
STRETCH = 13        # multi-mode: max q^T C q over the tail window (m^2; C = A / pi^2, the
                    # span's elongation is pi^2 / (2 l) times it); NaN for one mode
CLAMP_SHEAR = 14    # multi-mode: max |F_e| over both clamps e and the tail window (m; the
                    # transverse reaction is EI / l^3 times it: kernels.modes.span_loads); NaN
                    # for one mode
# A random base acceleration (the record kind, kernels.excitation): over the statistics window
# (the tail window; kernels.trajectory.observe_random), NaN otherwise
RMS_DEFLECTION = 15  # RMS of q (m)
RMS_VELOCITY = 16   # RMS of q' (m/s)
RMS_ACCELERATION = 17  # RMS of the absolute acceleration q'' + a_b (m/s^2)
ZERO_RATE = 18      # up-crossings of q = 0 per second (1/s)
LEVEL_RATE = 19     # level k's up-crossings by |q| per second (1/s) at LEVEL_RATE + k
WINDOW = LEVEL_RATE + MAX_LEVELS  # the statistics window's length (s)
RMS_RELATIVE = WINDOW + 1  # RMS of q'' (m/s^2): with RMS_DEFLECTION and RMS_VELOCITY, q's
                    # spectral moments m0, m2, m4 are their squares
CURVATURE_M0 = RMS_RELATIVE + 1  # several modes, with the loads observed: the mean square
                    # over the statistics window of the clamp's curvature times l^2, c(t) =
                    # sum phi_n''(0) q_n (m^2); + 1: of its rate (m^2/s^2); + 2: of its second
                    # derivative (m^2/s^4): c's spectral moments m0, m2, m4
MID_CURVATURE_M0 = CURVATURE_M0 + 3  # the same three of the midspan's, sum phi_n''(1/2) q_n
SPAN_PLACE = MID_CURVATURE_M0 + 3  # multi-mode: where SPAN_MAX occurred, x / l (0 to 1, from
                    # the clamp at x = 0); NaN for one mode
N_REALS = SPAN_PLACE + 1

# Columns of the `counts` output.
STEPS = 0           # accepted steps
REJECTED = 1        # rejected step attempts
RHS_EVALS = 2       # right-hand-side evaluations
N_COUNTS = 3

# A random base acceleration's records (sweep.models.random.Records, the kernels' `base`
# switch of the record kind), (R, N, RECORD_ROWS): per record and sample its a_b (m/s^2), its
# derivative (m/s^3), the running integrals of the record's cubic Hermite interpolant and of
# the interpolant's square from 0 to that sample (m/s, m^2/s^3;
# kernels.excitation.record_integrals) and the coefficients of u^2 and u^3 of the piece from
# that sample (m/s^2; kernels.excitation.CUBIC_C, CUBIC_D), side by side: a read of a piece
# touches one or two cache lines.
RECORD_ROWS = 6
