"""Layouts of the longitudinal (central-difference) kernel: its parameter columns, settings
vector, output columns and state flags. Plain constants, no Numba: the sweep layer reads them
(scene rules, dataset assembly) without importing a kernel.
"""

# Columns of a parameter row.
LENGTH = 0          # l (m)
WAVE_SPEED = 1      # a = sqrt(E/rho) (m/s)
AXIAL_STIFFNESS = 2  # EA (N)
LOAD = 3            # P0 (N), compression positive
T_END = 4           # end time (s)
BOUND = 5           # |u| beyond which the point is diverged (m)
N_PARAMS = 6
PARAM_NAMES = ("length", "wave_speed", "axial_stiffness", "load", "t_end", "bound")

# Entries of the settings vector.
INTERVALS = 0       # N, spatial intervals per span
COURANT = 1         # C = a dt / dx
SAMPLE_DT = 2       # history sample interval (s); used only when histories have columns
MAX_LEVELS = 3      # bound on time levels per span; a span that needs more stops there
N_SETTINGS = 4

LEVEL_LIMIT = 2.0 ** 62
"""Most time levels a span can count (int64 with room): a larger MAX_LEVELS is capped here.
A span whose level count t_end / dt is not finite (dt underflowed to 0, or the quotient
overflowed) is INVALID_INPUT; one that needs more levels than the budget is MAX_STEPS."""

# Columns of the `reals` output.
PEAK_END_DISPLACEMENT = 0   # max |u(l, t)| (m)
PEAK_FIXED_END_FORCE = 1    # max |N(0, t)| (N)
ARRIVAL_TIME = 2            # first time |N(0, t)| reaches |P0|, half the 2 P0 step (s)
PERIOD = 3                  # mean time between successive arrivals at the fixed end (s)
FAILURE_TIME = 4            # time at which a diverged point stopped (s) or NaN
TIME_STEP = 5               # dt (s)
N_REALS = 6

# State flags: the shared table of kernels/states.py (an integer means the same for every kind).
from .states import COMPLETED, DIVERGED, INVALID_INPUT, MAX_STEPS  # noqa: E402,F401
from .states import LONGITUDINAL_STATES as STATES  # noqa: E402,F401  (the flags this kernel gives)
