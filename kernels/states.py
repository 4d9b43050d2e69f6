"""The state table: the integer flag of every grid point's outcome, one table for every model
kind (an integer never means two things). Plain constants, no Numba: the sweep layer reads
them (dataset flags, scene rules) without compiling or importing a kernel. Their meanings are
in kernels/metrics.py's docstring and docs/model.md sec. 3.
"""

INVALID_INPUT = 0
DECAYED = 1
STEADY = 2
MODULATED = 3
UNSETTLED = 4
DIVERGED = 5
STEP_TOO_SMALL = 6
MAX_STEPS = 7
COMPLETED = 8         # the run reached t_end, and it has no settling to judge (a longitudinal
                      # span; a transverse span under a sine sweep)
RUNNING = -1
SECOND_PASS = -2      # internal: STEADY at rest away from zero, its settling time still to be found
                      # by transverse.settle_second_pass; never left in a result
OFF_MIDSPAN = -3      # internal: the midspan deflection decayed while a mode with a node there
                      # kept moving; judged again on that mode by modal_driver.judge_off_midspan
HIDDEN_MODE = -5      # internal: the midspan deflection steady while a mode with a node there
                      # still moves (above the settling band of the peak); judged again on
                      # that mode by modal_driver.judge_off_midspan
NOT_SOLVED = -4       # internal: a row no kernel has finished yet (sweep.threads writes it before
                      # a block runs, and reports rows as they turn final); every final state is
                      # >= 0

# STATE_MEANINGS[flag] is the CF flag_meaning of `flag`.
STATE_MEANINGS = ("invalid_input", "decayed", "steady", "modulated", "unsettled", "diverged",
                  "step_size_too_small", "max_steps_reached", "completed")
# The flags each model kind can produce (its dataset's `state` flag_values).
TRANSVERSE_STATES = (INVALID_INPUT, DECAYED, STEADY, MODULATED, UNSETTLED, DIVERGED,
                     STEP_TOO_SMALL, MAX_STEPS)
LONGITUDINAL_STATES = (INVALID_INPUT, COMPLETED, DIVERGED, MAX_STEPS)
SWEPT_STATES = (INVALID_INPUT, COMPLETED, DIVERGED, STEP_TOO_SMALL, MAX_STEPS)
"""A transverse scene with a swept base frequency: a sweep never settles."""
