"""Dormand-Prince 8(5,3) (DOP853) for the modal oscillator, step for step as SciPy's DOP853.

The tableau, the combined fifth/third-order error norm, the initial-step order and the
step-size controller are those of `scipy.integrate._ivp.rk.DOP853` (SciPy 1.17; Hairer,
Norsett & Wanner, Solving ODEs I, Sec. II.10), so that on the same problem a kernel accepts and
rejects the same steps as ``solve_ivp(method="DOP853")`` up to round-off. Twelve right-hand
sides per attempt (the last, f(t + h, y_new), is the next step's first), against RK45's six,
but steps about three times as long at the same error on this oscillator: fewer attempts.

Dense output, two of them. DOP853's own seventh-order interpolant (`dense_output`, as SciPy's
`Dop853DenseOutput`) costs three more right-hand sides, paid only on a step whose dense output
something needs (an extremum of q, the tail's start, a threshold crossing, a time-series
sample); with it the amplitudes are those of SciPy's DOP853 to round-off. The quintic Hermite
interpolant of q through q, q' and q'' at both ends of the step (`hermite_coefficients`) needs
no further stage; its error is of order h^6 (about 2e-5 (omega h)^6 of the amplitude at the
step's middle), and since DOP853's steps shrink only as rtol^(1/8), it outgrows the
integration's own error as rtol tightens: on the work-precision points it adds 3 % to the
amplitude error at rtol 1e-5, doubles it at 1e-6 and makes it 23x at 1e-8. So the one-mode
drivers take the seventh-order interpolant where rtol < SEVENTH_ORDER_BELOW_RTOL and the
Hermite one above (and always for a random record: trajectory.interpolant); the modal
drivers, whose midspan deflection is a projection of N modes, always the Hermite one.
The state is y = (q, q') in (m, m/s).

Coefficients: SciPy's `dop853_coefficients` (BSD-3-Clause), from Hairer's DOP853 Fortran code.
"""

import math

import numba as nb
import numpy as np

from .dopri5 import explicit_rk_step
from .oscillator import acceleration

N_STAGES = 12
ERROR_ESTIMATOR_ORDER = 7
ERROR_EXPONENT = -1.0 / (ERROR_ESTIMATOR_ORDER + 1)
RHS_PER_ATTEMPT = 12        # stages 2..12 and f(t + h, y_new)
ERR3_WEIGHT = 0.01          # SciPy: err = |h| e5^2 / sqrt((e5^2 + 0.01 e3^2) n)

C = np.array([
    0.0,
    0.526001519587677318785587544488e-01,
    0.789002279381515978178381316732e-01,
    0.118350341907227396726757197510,
    0.281649658092772603273242802490,
    0.333333333333333333333333333333,
    0.25,
    0.307692307692307692307692307692,
    0.651282051282051282051282051282,
    0.6,
    0.857142857142857142857142857142,
    1.0])

A = np.zeros((N_STAGES + 1, N_STAGES))    # row N_STAGES: the weights B
A[1, 0] = 5.26001519587677318785587544488e-2
A[2, 0] = 1.97250569845378994544595329183e-2
A[2, 1] = 5.91751709536136983633785987549e-2
A[3, 0] = 2.95875854768068491816892993775e-2
A[3, 2] = 8.87627564304205475450678981324e-2
A[4, 0] = 2.41365134159266685502369798665e-1
A[4, 2] = -8.84549479328286085344864962717e-1
A[4, 3] = 9.24834003261792003115737966543e-1
A[5, 0] = 3.7037037037037037037037037037e-2
A[5, 3] = 1.70828608729473871279604482173e-1
A[5, 4] = 1.25467687566822425016691814123e-1
A[6, 0] = 3.7109375e-2
A[6, 3] = 1.70252211019544039314978060272e-1
A[6, 4] = 6.02165389804559606850219397283e-2
A[6, 5] = -1.7578125e-2
A[7, 0] = 3.70920001185047927108779319836e-2
A[7, 3] = 1.70383925712239993810214054705e-1
A[7, 4] = 1.07262030446373284651809199168e-1
A[7, 5] = -1.53194377486244017527936158236e-2
A[7, 6] = 8.27378916381402288758473766002e-3
A[8, 0] = 6.24110958716075717114429577812e-1
A[8, 3] = -3.36089262944694129406857109825
A[8, 4] = -8.68219346841726006818189891453e-1
A[8, 5] = 2.75920996994467083049415600797e1
A[8, 6] = 2.01540675504778934086186788979e1
A[8, 7] = -4.34898841810699588477366255144e1
A[9, 0] = 4.77662536438264365890433908527e-1
A[9, 3] = -2.48811461997166764192642586468
A[9, 4] = -5.90290826836842996371446475743e-1
A[9, 5] = 2.12300514481811942347288949897e1
A[9, 6] = 1.52792336328824235832596922938e1
A[9, 7] = -3.32882109689848629194453265587e1
A[9, 8] = -2.03312017085086261358222928593e-2
A[10, 0] = -9.3714243008598732571704021658e-1
A[10, 3] = 5.18637242884406370830023853209
A[10, 4] = 1.09143734899672957818500254654
A[10, 5] = -8.14978701074692612513997267357
A[10, 6] = -1.85200656599969598641566180701e1
A[10, 7] = 2.27394870993505042818970056734e1
A[10, 8] = 2.49360555267965238987089396762
A[10, 9] = -3.0467644718982195003823669022
A[11, 0] = 2.27331014751653820792359768449
A[11, 3] = -1.05344954667372501984066689879e1
A[11, 4] = -2.00087205822486249909675718444
A[11, 5] = -1.79589318631187989172765950534e1
A[11, 6] = 2.79488845294199600508499808837e1
A[11, 7] = -2.85899827713502369474065508674
A[11, 8] = -8.87285693353062954433549289258
A[11, 9] = 1.23605671757943030647266201528e1
A[11, 10] = 6.43392746015763530355970484046e-1
A[12, 0] = 5.42937341165687622380535766363e-2
A[12, 5] = 4.45031289275240888144113950566
A[12, 6] = 1.89151789931450038304281599044
A[12, 7] = -5.8012039600105847814672114227
A[12, 8] = 3.1116436695781989440891606237e-1
A[12, 9] = -1.52160949662516078556178806805e-1
A[12, 10] = 2.01365400804030348374776537501e-1
A[12, 11] = 4.47106157277725905176885569043e-2
B = A[N_STAGES].copy()
A = A[:N_STAGES].copy()

# The dense output's three extra stages (rows N_STAGES + 1 .. N_STAGES_EXTENDED - 1 of the
# extended K; row N_STAGES is f(t + h, y_new)) and its interpolator matrix D.
N_STAGES_EXTENDED = 16
RHS_DENSE = N_STAGES_EXTENDED - N_STAGES - 1     # right-hand sides the dense output adds
SEVENTH_ORDER_BELOW_RTOL = 3e-6                  # rtol below which the one-mode drivers read
                                                 # the dense output off `dense_output`
C_EXTRA = np.array([0.1, 0.2, 7.0 / 9.0])
A_EXTRA = np.zeros((RHS_DENSE, N_STAGES_EXTENDED))
A_EXTRA[0, 0] = 5.61675022830479523392909219681e-2
A_EXTRA[0, 6] = 2.53500210216624811088794765333e-1
A_EXTRA[0, 7] = -2.46239037470802489917441475441e-1
A_EXTRA[0, 8] = -1.24191423263816360469010140626e-1
A_EXTRA[0, 9] = 1.5329179827876569731206322685e-1
A_EXTRA[0, 10] = 8.20105229563468988491666602057e-3
A_EXTRA[0, 11] = 7.56789766054569976138603589584e-3
A_EXTRA[0, 12] = -8.298e-3
A_EXTRA[1, 0] = 3.18346481635021405060768473261e-2
A_EXTRA[1, 5] = 2.83009096723667755288322961402e-2
A_EXTRA[1, 6] = 5.35419883074385676223797384372e-2
A_EXTRA[1, 7] = -5.49237485713909884646569340306e-2
A_EXTRA[1, 10] = -1.08347328697249322858509316994e-4
A_EXTRA[1, 11] = 3.82571090835658412954920192323e-4
A_EXTRA[1, 12] = -3.40465008687404560802977114492e-4
A_EXTRA[1, 13] = 1.41312443674632500278074618366e-1
A_EXTRA[2, 0] = -4.28896301583791923408573538692e-1
A_EXTRA[2, 5] = -4.69762141536116384314449447206
A_EXTRA[2, 6] = 7.68342119606259904184240953878
A_EXTRA[2, 7] = 4.06898981839711007970213554331
A_EXTRA[2, 8] = 3.56727187455281109270669543021e-1
A_EXTRA[2, 12] = -1.39902416515901462129418009734e-3
A_EXTRA[2, 13] = 2.9475147891527723389556272149
A_EXTRA[2, 14] = -9.15095847217987001081870187138

D = np.zeros((4, N_STAGES_EXTENDED))
D[0, 0] = -0.84289382761090128651353491142e+1
D[0, 5] = 0.56671495351937776962531783590
D[0, 6] = -0.30689499459498916912797304727e+1
D[0, 7] = 0.23846676565120698287728149680e+1
D[0, 8] = 0.21170345824450282767155149946e+1
D[0, 9] = -0.87139158377797299206789907490
D[0, 10] = 0.22404374302607882758541771650e+1
D[0, 11] = 0.63157877876946881815570249290
D[0, 12] = -0.88990336451333310820698117400e-1
D[0, 13] = 0.18148505520854727256656404962e+2
D[0, 14] = -0.91946323924783554000451984436e+1
D[0, 15] = -0.44360363875948939664310572000e+1
D[1, 0] = 0.10427508642579134603413151009e+2
D[1, 5] = 0.24228349177525818288430175319e+3
D[1, 6] = 0.16520045171727028198505394887e+3
D[1, 7] = -0.37454675472269020279518312152e+3
D[1, 8] = -0.22113666853125306036270938578e+2
D[1, 9] = 0.77334326684722638389603898808e+1
D[1, 10] = -0.30674084731089398182061213626e+2
D[1, 11] = -0.93321305264302278729567221706e+1
D[1, 12] = 0.15697238121770843886131091075e+2
D[1, 13] = -0.31139403219565177677282850411e+2
D[1, 14] = -0.93529243588444783865713862664e+1
D[1, 15] = 0.35816841486394083752465898540e+2
D[2, 0] = 0.19985053242002433820987653617e+2
D[2, 5] = -0.38703730874935176555105901742e+3
D[2, 6] = -0.18917813819516756882830838328e+3
D[2, 7] = 0.52780815920542364900561016686e+3
D[2, 8] = -0.11573902539959630126141871134e+2
D[2, 9] = 0.68812326946963000169666922661e+1
D[2, 10] = -0.10006050966910838403183860980e+1
D[2, 11] = 0.77771377980534432092869265740
D[2, 12] = -0.27782057523535084065932004339e+1
D[2, 13] = -0.60196695231264120758267380846e+2
D[2, 14] = 0.84320405506677161018159903784e+2
D[2, 15] = 0.11992291136182789328035130030e+2
D[3, 0] = -0.25693933462703749003312586129e+2
D[3, 5] = -0.15418974869023643374053993627e+3
D[3, 6] = -0.23152937917604549567536039109e+3
D[3, 7] = 0.35763911791061412378285349910e+3
D[3, 8] = 0.93405324183624310003907691704e+2
D[3, 9] = -0.37458323136451633156875139351e+2
D[3, 10] = 0.10409964950896230045147246184e+3
D[3, 11] = 0.29840293426660503123344363579e+2
D[3, 12] = -0.43533456590011143754432175058e+2
D[3, 13] = 0.96324553959188282948394950600e+2
D[3, 14] = -0.39177261675615439165231486172e+2
D[3, 15] = -0.14972683625798562581422125276e+3

# Error estimators (length N_STAGES + 1; f(t + h, y_new) has weight 0 in both).
E3 = np.zeros(N_STAGES + 1)
E3[:-1] = B
E3[0] -= 0.244094488188976377952755905512
E3[8] -= 0.733846688281611857341361741547
E3[11] -= 0.220588235294117647058823529412e-1
E5 = np.zeros(N_STAGES + 1)
E5[0] = 0.1312004499419488073250102996e-1
E5[5] = -0.1225156446376204440720569753e+1
E5[6] = -0.4957589496572501915214079952
E5[7] = 0.1664377182454986536961530415e+1
E5[8] = -0.3503288487499736816886487290
E5[9] = 0.3341791187130174790297318841
E5[10] = 0.8192320648511571246570742613e-1
E5[11] = -0.2235530786388629525884427845e-1


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def rk_step(t, y, h, p, K, y_new, parametric, base):
    """One DOP853 step of size h (s) from (t, y); K (N_STAGES + 1, 2), K[0] must hold f(t, y).

    Fills K[1..11] with the stage derivatives, K[12] with f(t + h, y_new) and y_new with the
    eighth-order solution. Twelve right-hand-side evaluations.
    """
    explicit_rk_step(t, y, h, p, K, y_new, A, B, C, parametric, base)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def combined_error_norm(e5q, e5v, e3q, e3v, h, sq, sv):
    """SciPy DOP853's error norm from the fifth- and third-order estimates (K^T E5, K^T E3 per
    component, not yet times h) and the scales sq, sv (atol + rtol max(|y|, |y_new|))."""
    e5q /= sq
    e5v /= sv
    e3q /= sq
    e3v /= sv
    e5 = e5q * e5q + e5v * e5v
    e3 = e3q * e3q + e3v * e3v
    err = abs(h) * e5 / math.sqrt((e5 + ERR3_WEIGHT * e3) * 2.0)
    return 0.0 if (e5 == 0.0) & (e3 == 0.0) else err     # a select: vectorises in the lanes


@nb.njit(cache=True, nogil=True, error_model="numpy", _nrt=False)
def error_norm(K, h, y, y_new, rtol, atol_q, atol_v):
    """SciPy DOP853's error norm of the attempt in K (see `combined_error_norm`); absolute
    tolerances atol_q (m) for q and atol_v (m/s) for q'."""
    e5q = 0.0
    e5v = 0.0
    e3q = 0.0
    e3v = 0.0
    for j in range(N_STAGES + 1):
        e5q += K[j, 0] * E5[j]
        e5v += K[j, 1] * E5[j]
        e3q += K[j, 0] * E3[j]
        e3v += K[j, 1] * E3[j]
    sq = atol_q + max(abs(y[0]), abs(y_new[0])) * rtol
    sv = atol_v + max(abs(y[1]), abs(y_new[1])) * rtol
    return combined_error_norm(e5q, e5v, e3q, e3v, h, sq, sv)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def hermite_terms(q0, v0, a0, q1, v1, a1, h):
    """(c3, c4, c5) of the quintic Hermite interpolant over a step of size h (s) through q (m),
    q' (m/s) and q'' (m/s^2) at its start (q0, v0, a0) and end (q1, v1, a1):
    q(x) = q0 + h v0 x + h^2 a0 x^2 / 2 + c3 x^3 + c4 x^4 + c5 x^5 (m), x = (t - t_old)/h."""
    d0 = q1 - q0 - h * v0 - 0.5 * h * h * a0       # what the quadratic start misses at x = 1
    d1 = h * (v1 - v0) - h * h * a0                 # ... in h q'
    d2 = h * h * (a1 - a0)                          # ... in h^2 q''
    return (10.0 * d0 - 4.0 * d1 + 0.5 * d2,
            -15.0 * d0 + 7.0 * d1 - d2,
            6.0 * d0 - 3.0 * d1 + 0.5 * d2)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def hermite_coefficients(q0, v0, a0, q1, v1, a1, h, Qc):
    """The quintic Hermite interpolant (`hermite_terms`) in the layout of
    dopri5.dense_coefficients: q(x) = q0 + h x (Qc[0, 0] + x (Qc[0, 1] + ...)), and its
    derivative q'(x) = v0 + h x (Qc[1, 0] + ...), a quartic (Qc[1, 4:] = 0, Qc[0, 5:] = 0)."""
    c3, c4, c5 = hermite_terms(q0, v0, a0, q1, v1, a1, h)
    Qc[0, 0] = v0
    Qc[0, 1] = 0.5 * h * a0
    Qc[0, 2] = c3 / h
    Qc[0, 3] = c4 / h
    Qc[0, 4] = c5 / h
    Qc[1, 0] = a0
    Qc[1, 1] = 3.0 * c3 / (h * h)
    Qc[1, 2] = 4.0 * c4 / (h * h)
    Qc[1, 3] = 5.0 * c5 / (h * h)
    Qc[1, 4] = 0.0
    Qc[0, 5] = 0.0
    Qc[0, 6] = 0.0
    Qc[1, 5] = 0.0
    Qc[1, 6] = 0.0


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def dense_output(t, q0, v0, q1, v1, h, p, o, s, K, Qc, fast, parametric, base):
    """DOP853's seventh-order interpolant of the accepted step of size h (s) from (t, q0, v0)
    to (q1, v1) (s, m, m/s), as SciPy's `DOP853._dense_output_impl` and `Dop853DenseOutput`,
    into Qc (2, DENSE_TERMS) in the layout of dopri5.dense_coefficients: y_i(x) = y_i(0) +
    h x (Qc[i, 0] + x (Qc[i, 1] + ... + x Qc[i, 6])), x = (t' - t)/h.

    K (N_STAGES_EXTENDED, 2) holds the step's stages in rows 0..N_STAGES (row N_STAGES:
    f(t + h, y_new)); its rows N_STAGES + 1.. get the three extra stages (A_EXTRA, C_EXTRA:
    three right-hand sides). p[o + column * s]: the point's prepared row; fast: the right-hand
    side's cosine switch (oscillator.acceleration).

    SciPy writes the interpolant as y_old + x (F0 + (1 - x) (F1 + x (F2 + (1 - x) (F3 + x (F4 +
    (1 - x) (F5 + x F6)))))), F0 = dy, F1 = h f_old - dy, F2 = 2 dy - h (f_new + f_old),
    F3..F6 = h D K; expanding the nested products gives the powers of x below. Every sum over
    the step's own stages is taken in one pass (fourteen independent chains of fused
    multiply-adds, not seven in a row), the extra stages' terms after (measured on the
    reference sweep at rtol 1e-8, DOP853 lanes: 1.15x the Hermite version's time this way,
    1.20-1.31x with the sums in a row)."""
    a0q = 0.0
    a0v = 0.0
    a1q = 0.0
    a1v = 0.0
    a2q = 0.0
    a2v = 0.0
    d0q = 0.0
    d0v = 0.0
    d1q = 0.0
    d1v = 0.0
    d2q = 0.0
    d2v = 0.0
    d3q = 0.0
    d3v = 0.0
    for j in range(N_STAGES + 1):
        kq = K[j, 0]
        kv = K[j, 1]
        a0q += A_EXTRA[0, j] * kq
        a0v += A_EXTRA[0, j] * kv
        a1q += A_EXTRA[1, j] * kq
        a1v += A_EXTRA[1, j] * kv
        a2q += A_EXTRA[2, j] * kq
        a2v += A_EXTRA[2, j] * kv
        d0q += D[0, j] * kq
        d0v += D[0, j] * kv
        d1q += D[1, j] * kq
        d1v += D[1, j] * kv
        d2q += D[2, j] * kq
        d2v += D[2, j] * kv
        d3q += D[3, j] * kq
        d3v += D[3, j] * kv
    r0 = N_STAGES + 1
    v = v0 + a0v * h
    K[r0, 0] = v
    K[r0, 1] = acceleration(t + C_EXTRA[0] * h, q0 + a0q * h, v, p, o, s, fast, parametric, base)
    a1q += A_EXTRA[1, r0] * K[r0, 0]
    a1v += A_EXTRA[1, r0] * K[r0, 1]
    a2q += A_EXTRA[2, r0] * K[r0, 0]
    a2v += A_EXTRA[2, r0] * K[r0, 1]
    v = v0 + a1v * h
    K[r0 + 1, 0] = v
    K[r0 + 1, 1] = acceleration(t + C_EXTRA[1] * h, q0 + a1q * h, v, p, o, s, fast,
                                parametric, base)
    a2q += A_EXTRA[2, r0 + 1] * K[r0 + 1, 0]
    a2v += A_EXTRA[2, r0 + 1] * K[r0 + 1, 1]
    v = v0 + a2v * h
    K[r0 + 2, 0] = v
    K[r0 + 2, 1] = acceleration(t + C_EXTRA[2] * h, q0 + a2q * h, v, p, o, s, fast,
                                parametric, base)
    for j in range(r0, N_STAGES_EXTENDED):
        d0q += D[0, j] * K[j, 0]
        d0v += D[0, j] * K[j, 1]
        d1q += D[1, j] * K[j, 0]
        d1v += D[1, j] * K[j, 1]
        d2q += D[2, j] * K[j, 0]
        d2v += D[2, j] * K[j, 1]
        d3q += D[3, j] * K[j, 0]
        d3v += D[3, j] * K[j, 1]
    inv_h = 1.0 / h          # the h of h D K and the 1/h of the layout cancel
    _dense_row(Qc, 0, q1 - q0, K[0, 0], K[N_STAGES, 0], h, inv_h, d0q, d1q, d2q, d3q)
    _dense_row(Qc, 1, v1 - v0, K[0, 1], K[N_STAGES, 1], h, inv_h, d0v, d1v, d2v, d3v)


@nb.njit(cache=True, nogil=True, error_model="numpy", inline="always")
def _dense_row(Qc, i, dy, f_old, f_new, h, inv_h, f3, f4, f5, f6):
    """Row i of `dense_output`'s coefficients from component i's dy, f_old, f_new and D K."""
    f1 = h * f_old - dy
    f2 = 2.0 * dy - h * (f_new + f_old)
    Qc[i, 0] = (dy + f1) * inv_h
    Qc[i, 1] = (f2 - f1) * inv_h + f3
    Qc[i, 2] = -f2 * inv_h - 2.0 * f3 + f4 + f5
    Qc[i, 3] = f3 - 2.0 * f4 - 3.0 * f5 + f6
    Qc[i, 4] = f4 + 3.0 * f5 - 3.0 * f6
    Qc[i, 5] = 3.0 * f6 - f5
    Qc[i, 6] = -f6
