/* The soft finger swinging under gravity, integrated in plain C from its
 * exported equations with a fixed step (classical Runge-Kutta), as a
 * controller's loop would. Build and run:
 *
 *   softarm export soft_finger --c build/c
 *   cc -std=c99 -O2 -I build/c examples/c/swing.c build/c/soft_finger.c -lm -o swing
 *   ./swing > swing.csv
 *
 * It prints t, tip_x, tip_y (m) every 10 ms: the same motion as
 * `softarm simulate soft_finger --t-end 2`. */
#include <stdio.h>

#include "soft_finger.h"

#define NX SOFT_FINGER_NX

/* x += h * dx, into y. */
static void axpy(double *y, const double *x, double h, const double *dx)
{
    int i;
    for (i = 0; i < NX; i++) y[i] = x[i] + h * dx[i];
}

/* One classical Runge-Kutta step of size h; nonzero if M(q) failed. */
static int rk4(soft_finger_model *m, double t, double *x, double h)
{
    static double k1[NX], k2[NX], k3[NX], k4[NX], y[NX];
    int i;
    if (soft_finger_state_derivative(m, t, x, k1)) return 1;
    axpy(y, x, h / 2, k1);
    if (soft_finger_state_derivative(m, t + h / 2, y, k2)) return 1;
    axpy(y, x, h / 2, k2);
    if (soft_finger_state_derivative(m, t + h / 2, y, k3)) return 1;
    axpy(y, x, h, k3);
    if (soft_finger_state_derivative(m, t + h, y, k4)) return 1;
    for (i = 0; i < NX; i++) x[i] += h / 6 * (k1[i] + 2 * k2[i] + 2 * k3[i] + k4[i]);
    return 0;
}

int main(void)
{
    /* The model and its workspace: static, as it is large for a stack. */
    static soft_finger_params params;
    static soft_finger_model model;
    double x[NX] = {0}, out[SOFT_FINGER_NOUTPUTS];
    const double h = 1e-4, t_end = 2.0;
    const int steps = (int)(t_end / h + 0.5), every = 100;
    int k;
    soft_finger_default_params(&params);
    soft_finger_init(&model, &params);
    printf("t,tip_x,tip_y\n");
    for (k = 0; k <= steps; k++) {
        double t = k * h;
        if (k % every == 0) {
            soft_finger_outputs(&model, t, x, x + SOFT_FINGER_NQ, out);
            printf("%.4f,%.9f,%.9f\n", t, out[0], out[1]);
        }
        if (k < steps && rk4(&model, t, x, h)) {
            fprintf(stderr, "the mass matrix is not positive definite at t = %g s\n", t);
            return 1;
        }
    }
    return 0;
}
