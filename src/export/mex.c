/* PFX_mex.c: the MATLAB and Octave gateway of the exported softarm model
 * PFX (PFX.h): one MEX function, its first argument the function's name.
 * The .m files beside it wrap each call; PFX_build.m compiles it. */
#include <stdio.h>
#include <string.h>

#include "mex.h"
#include "PFX.h"

/* The model, bound to its default values at the first call. */
static PFX_model model;
static PFX_params params;
static int ready = 0;

static const char *USAGE =
    "PFX_mex(NAME, ...): NAME is state_derivative (t, x), jacobian (t, x), mass (t, q), "
    "bias (t, q, qd), outputs (t, q, qd), parameters (), set_parameter (i, value), "
    "reset (), coordinate_names (), parameter_names (), output_names ()"
#ifdef PFXU_NPAIRS
    ", contact (t, x), contact_update (t, x)"
#endif
    ;

static void fail(const char *message) { mexErrMsgIdAndTxt("softarm:PFX", "%s", message); }

/* Argument k as n real values. */
static const double *values(int nrhs, const mxArray *prhs[], int k, size_t n, const char *what)
{
    static char message[160];
    if (k >= nrhs || !mxIsDouble(prhs[k]) || mxIsComplex(prhs[k]) ||
        mxGetNumberOfElements(prhs[k]) != n) {
        sprintf(message, "%s must be %lu real values", what, (unsigned long)n);
        fail(message);
    }
    return mxGetPr(prhs[k]);
}

static double scalar(int nrhs, const mxArray *prhs[], int k, const char *what)
{
    return values(nrhs, prhs, k, 1, what)[0];
}

/* A column of n values. */
static double *column(mxArray **out, size_t n)
{
    *out = mxCreateDoubleMatrix(n, 1, mxREAL);
    return mxGetPr(*out);
}

/* A row-major r x c matrix as MATLAB's column-major one. */
static void matrix(mxArray **out, const double *rows, size_t r, size_t c)
{
    size_t i, j;
    double *m;
    *out = mxCreateDoubleMatrix(r, c, mxREAL);
    m = mxGetPr(*out);
    for (i = 0; i < r; i++)
        for (j = 0; j < c; j++) m[j * r + i] = rows[i * c + j];
}

static void names(mxArray **out, const char *const *list, size_t n)
{
    size_t i;
    *out = mxCreateCellMatrix(n, 1);
    for (i = 0; i < n; i++) mxSetCell(*out, i, mxCreateString(list[i]));
}

static void status_check(int status)
{
    if (status == 1) fail("the mass matrix is not positive definite at this state");
    if (status == 2) fail("the joints are dependent at this state");
}

void mexFunction(int nlhs, mxArray *plhs[], int nrhs, const mxArray *prhs[])
{
    static double mass[PFXU_NQ * PFXU_NQ + 1], bias[PFXU_NQ + 1], jac[PFXU_NX * PFXU_NX + 1];
    static const double zeros[PFXU_NQ + 1];
    char name[40];
    (void)nlhs;
    if (!ready) {
        PFX_default_params(&params);
        PFX_init(&model, &params);
        ready = 1;
    }
    if (nrhs < 1 || !mxIsChar(prhs[0]) || mxGetString(prhs[0], name, sizeof name)) fail(USAGE);
    if (!strcmp(name, "state_derivative")) {
        double t = scalar(nrhs, prhs, 1, "t");
        const double *x = values(nrhs, prhs, 2, PFXU_NX, "x");
        status_check(PFX_state_derivative(&model, t, x, column(&plhs[0], PFXU_NX)));
    } else if (!strcmp(name, "jacobian")) {
        double t = scalar(nrhs, prhs, 1, "t");
        const double *x = values(nrhs, prhs, 2, PFXU_NX, "x");
        status_check(PFX_state_jacobian(&model, t, x, jac));
        matrix(&plhs[0], jac, PFXU_NX, PFXU_NX);
    } else if (!strcmp(name, "mass")) {
        double t = scalar(nrhs, prhs, 1, "t");
        const double *q = values(nrhs, prhs, 2, PFXU_NQ, "q");
        PFX_mass_bias(&model, t, q, zeros, mass, bias);
        matrix(&plhs[0], mass, PFXU_NQ, PFXU_NQ);
    } else if (!strcmp(name, "bias")) {
        double t = scalar(nrhs, prhs, 1, "t");
        const double *q = values(nrhs, prhs, 2, PFXU_NQ, "q");
        const double *qd = values(nrhs, prhs, 3, PFXU_NQ, "qd");
        PFX_mass_bias(&model, t, q, qd, mass, column(&plhs[0], PFXU_NQ));
    } else if (!strcmp(name, "outputs")) {
        double t = scalar(nrhs, prhs, 1, "t");
        const double *q = values(nrhs, prhs, 2, PFXU_NQ, "q");
        const double *qd = values(nrhs, prhs, 3, PFXU_NQ, "qd");
        PFX_outputs(&model, t, q, qd, column(&plhs[0], PFXU_NOUTPUTS));
#ifdef PFXU_NPAIRS
    } else if (!strcmp(name, "contact")) {
        /* Each pair's gap and normal force. */
        double t = scalar(nrhs, prhs, 1, "t");
        const double *x = values(nrhs, prhs, 2, PFXU_NX, "x");
        double *gap = column(&plhs[0], PFXU_NPAIRS), *normal;
        if (nlhs > 1) {
            normal = column(&plhs[1], PFXU_NPAIRS);
        } else {
            static double unused[PFXU_NPAIRS + 1];
            normal = unused;
        }
        PFX_contact(&model, t, x, gap, normal);
    } else if (!strcmp(name, "contact_update")) {
        /* The pairs' records, kept in this MEX function: call after each step. */
        double t = scalar(nrhs, prhs, 1, "t");
        const double *x = values(nrhs, prhs, 2, PFXU_NX, "x");
        PFX_contact_update(&model, t, x);
#endif
    } else if (!strcmp(name, "parameters")) {
        memcpy(column(&plhs[0], PFXU_NPARAMS), model.p, PFXU_NPARAMS * sizeof(double));
    } else if (!strcmp(name, "set_parameter")) {
        double i = scalar(nrhs, prhs, 1, "i");
        double v = scalar(nrhs, prhs, 2, "value");
        if (!(i >= 1 && i <= PFXU_NPARAMS) || i != (double)(size_t)i)
            fail("set_parameter's i is 1 to NPARAMS (parameter_names' order)");
        PFX_set_parameter(&model, (size_t)i - 1, v);
    } else if (!strcmp(name, "reset")) {
        PFX_init(&model, &params);
    } else if (!strcmp(name, "coordinate_names")) {
        names(&plhs[0], PFX_coordinate_names, PFXU_NQ);
    } else if (!strcmp(name, "parameter_names")) {
        names(&plhs[0], PFX_parameter_names, PFXU_NPARAMS);
    } else if (!strcmp(name, "output_names")) {
        names(&plhs[0], PFX_output_names, PFXU_NOUTPUTS);
    } else {
        fail(USAGE);
    }
}
