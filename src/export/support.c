/* softarm's support code, the same in every export (its names carry the
 * model's prefix, so that exports link together): the removable-
 * singularity functions and the Rodrigues coefficients the kernels call
 * (runtime::special and runtime::rodrigues, with the same branches), and
 * the L D L^T solve of the packed mass matrix. */

double sa_factorial(unsigned n)
{
    double acc = 1.0;
    unsigned i;
    for (i = 2; i <= n; i++) acc *= (double)i;
    return acc;
}

/* m (m - 1) ... (m - k + 1) */
double sa_falling(unsigned m, unsigned k)
{
    double acc = 1.0;
    unsigned i;
    for (i = 0; i < k; i++) acc *= (double)(m - i);
    return acc;
}

double sa_sign(double x)
{
    return x > 0.0 ? 1.0 : (x < 0.0 ? -1.0 : 0.0);
}

/* x^n by repeated squaring, as Rust's powi. */
double sa_powi(double x, int n)
{
    unsigned e = (unsigned)(n < 0 ? -n : n);
    double acc = 1.0, b = x;
    while (e) {
        if (e & 1u) acc *= b;
        b *= b;
        e >>= 1;
    }
    return n < 0 ? 1.0 / acc : acc;
}

/* 1/n! for n < 48. */
static const double sa_inv_factorial[48] = {/*INV_FACTORIALS*/};

/* d^k/dx^k of sum_j (-1)^j x^(first + 2j) / (first + 2j + shift)!, the
 * Taylor series of the three removable functions below |x| = 1, by
 * Horner in x^2 over the exponents m >= k; sixteen terms reach round-off
 * there for every order the kernels use. */
double sa_series(unsigned first, unsigned shift, unsigned k, double x)
{
    double x2 = x * x, sum = 0.0;
    unsigned m0 = first;
    int i;
    while (m0 < k) m0 += 2;
    for (i = 15; i >= 0; i--) {
        unsigned m = m0 + 2u * (unsigned)i, j = (m - first) / 2;
        double c = ((j % 2) ? -1.0 : 1.0) * sa_inv_factorial[m + shift] * sa_falling(m, k);
        sum = sum * x2 + c;
    }
    return sum * sa_powi(x, (int)(m0 - k));
}

/* i-th derivative of the numerator g of each function: 0 sin x (sinc),
 * 1 1 - cos x (cosc), 2 x - sin x (sinc_rem). */
double sa_numerator(int which, unsigned i, double x)
{
    double s = sin(x), c = cos(x);
    double sin_d[4], cos_d[4];
    sin_d[0] = s; sin_d[1] = c; sin_d[2] = -s; sin_d[3] = -c;
    cos_d[0] = c; cos_d[1] = -s; cos_d[2] = -c; cos_d[3] = s;
    switch (which) {
    case 0: return sin_d[i % 4];
    case 1: return i == 0 ? 1.0 - c : -cos_d[i % 4];
    default:
        if (i == 0) return x - s;
        if (i == 1) return 1.0 - c;
        return -sin_d[i % 4];
    }
}

/* d^k/dx^k [g(x) / x^p] by Leibniz. */
double sa_leibniz(int which, unsigned k, double x, unsigned p)
{
    double inv = 1.0 / x, sum = 0.0, xp = sa_powi(inv, (int)p);
    unsigned j;
    for (j = 0; j <= k; j++) {
        double sgn = (j % 2) ? -1.0 : 1.0;
        double rising = sa_factorial(p + j - 1) / sa_factorial(p - 1);
        double binomial = sa_falling(k, j) / sa_factorial(j);
        sum += binomial * sa_numerator(which, k - j, x) * sgn * rising * xp;
        xp *= inv;
    }
    return sum;
}

/* d^k/dx^k sin(x)/x */
double sa_sinc(unsigned k, double x)
{
    return fabs(x) < 1.0 ? sa_series(0, 1, k, x) : sa_leibniz(0, k, x, 1);
}

/* d^k/dx^k (1 - cos x)/x */
double sa_cosc(unsigned k, double x)
{
    return fabs(x) < 1.0 ? sa_series(1, 1, k, x) : sa_leibniz(1, k, x, 1);
}

/* d^k/dx^k (x - sin x)/x^3 */
double sa_sinc_rem(unsigned k, double x)
{
    return fabs(x) < 1.0 ? sa_series(0, 3, k, x) : sa_leibniz(2, k, x, 3);
}

/* d^n/dw^n c_j(w), c_j(w) = sum_k (-w)^k / (2k + j)!, summed until the
 * terms no longer change the sum. */
double sa_rodrigues_series(unsigned j, unsigned n, double w)
{
    double term = (n % 2) ? -1.0 : 1.0, sum;
    unsigned i, k = 0;
    for (i = 1; i <= n; i++) term *= (double)i;
    for (i = 1; i <= 2 * n + j; i++) term /= (double)i;
    sum = term;
    for (;;) {
        double a = (double)(2 * (k + n) + j), next;
        term *= -w * (double)(k + n + 1) / ((double)(k + 1) * (a + 1.0) * (a + 2.0));
        next = sum + term;
        k++;
        if (next == sum || k > 60) return next;
        sum = next;
    }
}

/* The closed forms in theta = sqrt|w| and the recurrence
 * 2 w c_j' = c_{j-1} - j c_j (orders below 16). */
double sa_rodrigues_closed(unsigned j, unsigned n, double w)
{
    double g[16][18];
    double theta = sqrt(fabs(w)), c0, c1;
    unsigned i, m;
    if (w > 0.0) {
        c0 = cos(theta);
        c1 = sin(theta) / theta;
    } else {
        c0 = cosh(theta);
        c1 = sinh(theta) / theta;
    }
    g[0][0] = c0;
    g[0][1] = c1;
    for (i = 2; i <= j + 1; i++) g[0][i] = (1.0 / sa_factorial(i - 2) - g[0][i - 2]) / w;
    for (m = 0; m < n; m++) {
        g[m + 1][0] = -g[m][1] / 2.0;
        for (i = 1; i <= j + 1; i++)
            g[m + 1][i] = (g[m][i - 1] - (double)(i + 2 * m) * g[m][i]) / (2.0 * w);
    }
    return g[n][j];
}

/* Every c_j (j <= 8) and its derivatives of orders 0..4 at w: below
 * |w| = 9 the two top members by their series and the rest downward from
 * c_j = 1/j! - w c_{j+2}; beyond it the closed forms. */
void sa_family(double w, double c[9][5])
{
    double a = fabs(w);
    int j, n;
    if (a < 9.0) {
        double inv_fact[9];
        inv_fact[0] = 1.0;
        for (j = 1; j < 9; j++) inv_fact[j] = inv_fact[j - 1] / (double)j;
        for (n = 0; n < 5; n++) {
            c[7][n] = sa_rodrigues_series(7, (unsigned)n, w);
            c[8][n] = sa_rodrigues_series(8, (unsigned)n, w);
        }
        for (j = 6; j >= 0; j--) {
            c[j][0] = inv_fact[j] - w * c[j + 2][0];
            for (n = 1; n < 5; n++) c[j][n] = -(w * c[j + 2][n]) - (double)n * c[j + 2][n - 1];
        }
    } else {
        for (j = 0; j < 9; j++)
            for (n = 0; n < 5; n++) c[j][n] = sa_rodrigues_closed((unsigned)j, (unsigned)n, w);
    }
}

/* d^n/dw^n c_j(w) beyond the family. */
double sa_rodrigues(unsigned j, unsigned n, double w)
{
    if (j < 9 && n < 5) {
        double c[9][5];
        sa_family(w, c);
        return c[j][n];
    }
    if (fabs(w) < 9.0) return sa_rodrigues_series(j, n, w);
    if (j < 16 && n < 15) return sa_rodrigues_closed(j, n, w);
    return NAN;
}

/* Index of (i, j), i <= j, in a packed upper triangle of order n. */
size_t sa_packed(size_t n, size_t i, size_t j)
{
    return i * n - i * (i - 1) / 2 + (j - i);
}

/* L D L^T of the packed symmetric matrix a (order n) into l (n x n, unit
 * lower, row-major) and d; 0 when it is positive definite. */
int sa_ldlt_factor(size_t n, const double *a, double *l, double *d)
{
    size_t i, j, k;
    for (j = 0; j < n; j++) {
        double djj = a[sa_packed(n, j, j)];
        for (k = 0; k < j; k++) djj -= l[j * n + k] * l[j * n + k] * d[k];
        if (!(djj > 0.0)) return 1;
        d[j] = djj;
        l[j * n + j] = 1.0;
        for (i = j + 1; i < n; i++) {
            double v = a[sa_packed(n, j, i)];
            for (k = 0; k < j; k++) v -= l[i * n + k] * l[j * n + k] * d[k];
            l[i * n + j] = v / djj;
        }
    }
    return 0;
}

/* Solve L D L^T x = b in place. */
void sa_ldlt_solve(size_t n, const double *l, const double *d, double *b)
{
    size_t i, k;
    for (i = 0; i < n; i++)
        for (k = 0; k < i; k++) b[i] -= l[i * n + k] * b[k];
    for (i = 0; i < n; i++) b[i] /= d[i];
    for (i = n; i-- > 0;)
        for (k = i + 1; k < n; k++) b[i] -= l[k * n + i] * b[k];
}

/* A kernel too large for straight-line code (it would take a C compiler
 * minutes) is a table of operations, run here: slot i holds operation i's
 * value, as in softarm's own tape interpreter. */
enum {
    SA_CONST, SA_Q, SA_QD, SA_QDD, SA_DIR, SA_PARAM, SA_TIME, SA_AUX,
    SA_ADD, SA_SUB, SA_MUL, SA_MULADD, SA_MULSUB, SA_NEGMULADD, SA_DIV, SA_NEG,
    SA_POWI, SA_POWF, SA_SQRT, SA_SIN, SA_COS, SA_TAN, SA_EXP, SA_LN, SA_ABS,
    SA_SIGN, SA_SINC, SA_COSC, SA_SINC_REM, SA_RODRIGUES,
    /* A member of a Rodrigues family (b = j, c = n) held in family f;
     * the first read of a family computes it. */
    SA_FAMILY_FIRST, SA_FAMILY
};

typedef struct {
    int op, a, b, c, f;
    double k;
} sa_op;

void sa_run(const sa_op *ops, size_t len, const unsigned *outs, size_t nout, double *s,
            double (*fam)[9][5], double t, const double *q, const double *qd, const double *qdd,
            const double *dir, const double *p, const double *aux, double *out)
{
    size_t i;
    for (i = 0; i < len; i++) {
        const sa_op *o = ops + i;
        double v;
        switch (o->op) {
        case SA_CONST: v = o->k; break;
        case SA_Q: v = q[o->a]; break;
        case SA_QD: v = qd[o->a]; break;
        case SA_QDD: v = qdd[o->a]; break;
        case SA_DIR: v = dir[o->a]; break;
        case SA_PARAM: v = p[o->a]; break;
        case SA_TIME: v = t; break;
        case SA_AUX: v = aux[o->a]; break;
        case SA_ADD: v = s[o->a] + s[o->b]; break;
        case SA_SUB: v = s[o->a] - s[o->b]; break;
        case SA_MUL: v = s[o->a] * s[o->b]; break;
        case SA_MULADD: v = fma(s[o->a], s[o->b], s[o->c]); break;
        case SA_MULSUB: v = fma(s[o->a], s[o->b], -s[o->c]); break;
        case SA_NEGMULADD: v = fma(-s[o->a], s[o->b], s[o->c]); break;
        case SA_DIV: v = s[o->a] / s[o->b]; break;
        case SA_NEG: v = -s[o->a]; break;
        case SA_POWI: v = sa_powi(s[o->a], o->b); break;
        case SA_POWF: v = pow(s[o->a], s[o->b]); break;
        case SA_SQRT: v = sqrt(s[o->a]); break;
        case SA_SIN: v = sin(s[o->a]); break;
        case SA_COS: v = cos(s[o->a]); break;
        case SA_TAN: v = tan(s[o->a]); break;
        case SA_EXP: v = exp(s[o->a]); break;
        case SA_LN: v = log(s[o->a]); break;
        case SA_ABS: v = fabs(s[o->a]); break;
        case SA_SIGN: v = sa_sign(s[o->a]); break;
        case SA_SINC: v = sa_sinc((unsigned)o->b, s[o->a]); break;
        case SA_COSC: v = sa_cosc((unsigned)o->b, s[o->a]); break;
        case SA_SINC_REM: v = sa_sinc_rem((unsigned)o->b, s[o->a]); break;
        case SA_RODRIGUES: v = sa_rodrigues((unsigned)o->b, (unsigned)o->c, s[o->a]); break;
        case SA_FAMILY_FIRST: sa_family(s[o->a], fam[o->f]); v = fam[o->f][o->b][o->c]; break;
        case SA_FAMILY: v = fam[o->f][o->b][o->c]; break;
        default: v = NAN; break;
        }
        s[i] = v;
    }
    for (i = 0; i < nout; i++) out[i] = s[outs[i]];
}
