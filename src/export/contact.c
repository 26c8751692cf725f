/* Contact (softarm's runtime::contact, in f64): the obstacles' signed
 * distances and outward normals, the normal laws and regularised Coulomb
 * friction, each as softarm computes it, in its order. */

/* Obstacle kinds and the numbers of each (sa_obstacle.v). */
#define SA_PLANE 0    /* point (3), unit normal (3) */
#define SA_SPHERE 1   /* centre (3), radius */
#define SA_CYLINDER 2 /* centre (3), unit axis (3), radius, half length */
#define SA_BOX 3      /* centre (3), rotation (9, row-major: columns the box's axes), half sizes (3) */

/* Normal laws (sa_law.kind) and their numbers. */
#define SA_SPRING_DASHPOT 0 /* F = k d + c d' */
#define SA_HERTZ 1          /* F = k d^n */
#define SA_HC_GIVEN 2       /* F = k d^n + b d^n d' (b = k alpha given) */
#define SA_HC_RESTITUTION 3 /* F = k d^n (1 + a / v_in d'), a from the restitution */

static double sa_dot3(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

static double sa_norm3(const double *a) { return sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]); }

/* Rust's signum: +1 for +0.0, -1 for -0.0. */
static double sa_signum(double x) { return copysign(1.0, x); }

/* A unit vector along a, or the fallback where a vanishes. */
static void sa_unit3(const double *a, const double *fallback, double *out)
{
    double len = sa_norm3(a);
    int k;
    for (k = 0; k < 3; k++) out[k] = len <= DBL_EPSILON ? fallback[k] : a[k] / len;
}

/* A unit vector normal to the unit vector a. */
static void sa_perpendicular(const double *a, double *out)
{
    double e[3] = {0.0, 0.0, 0.0}, c[3], len;
    int k;
    e[fabs(a[0]) < 0.9 ? 0 : 1] = 1.0;
    c[0] = a[1] * e[2] - a[2] * e[1];
    c[1] = a[2] * e[0] - a[0] * e[2];
    c[2] = a[0] * e[1] - a[1] * e[0];
    len = sa_norm3(c);
    for (k = 0; k < 3; k++) out[k] = c[k] / len;
}

static double sa_cylinder(const double *rel, const double *axis, double radius, double half, double *n)
{
    double h = sa_dot3(rel, axis), radial[3], r, fallback[3], out_r, out_h, along[3], radial_n[3];
    int k;
    for (k = 0; k < 3; k++) radial[k] = rel[k] - h * axis[k];
    r = sa_norm3(radial);
    sa_perpendicular(axis, fallback);
    out_r = r - radius;
    out_h = fabs(h) - half;
    for (k = 0; k < 3; k++) along[k] = axis[k] * sa_signum(h);
    sa_unit3(radial, fallback, radial_n);
    if (out_r > 0.0 && out_h > 0.0) {
        double d = sqrt(out_r * out_r + out_h * out_h);
        for (k = 0; k < 3; k++) n[k] = (radial_n[k] * out_r + along[k] * out_h) / d;
        return d;
    }
    if (out_r > 0.0 || (out_h <= 0.0 && out_r > out_h)) {
        for (k = 0; k < 3; k++) n[k] = radial_n[k];
        return out_r;
    }
    for (k = 0; k < 3; k++) n[k] = along[k];
    return out_h;
}

static double sa_box(const double *rel, const double *rot, const double *half, double *n)
{
    double local[3], excess[3], v[3] = {0.0, 0.0, 0.0}, n_local[3] = {0.0, 0.0, 0.0}, d;
    int i, k, outside = 0;
    for (i = 0; i < 3; i++) {
        double axis[3];
        axis[0] = rot[i];
        axis[1] = rot[3 + i];
        axis[2] = rot[6 + i];
        local[i] = sa_dot3(rel, axis);
        excess[i] = fabs(local[i]) - half[i];
        if (excess[i] > 0.0) outside = 1;
    }
    if (!outside) {
        /* The nearest face (the last of equals, as Rust's max_by). */
        int best = 0;
        for (i = 1; i < 3; i++)
            if (excess[i] >= excess[best]) best = i;
        n_local[best] = sa_signum(local[best]);
        d = excess[best];
    } else {
        for (i = 0; i < 3; i++)
            if (excess[i] > 0.0) v[i] = excess[i] * sa_signum(local[i]);
        d = sa_norm3(v);
        for (i = 0; i < 3; i++) n_local[i] = v[i] / d;
    }
    for (k = 0; k < 3; k++) n[k] = n_local[0] * rot[3 * k] + n_local[1] * rot[3 * k + 1] + n_local[2] * rot[3 * k + 2];
    return d;
}

/* The signed distance of p from an obstacle (negative inside) and its
 * outward normal n. */
static double sa_distance(int kind, const double *v, const double *p, double *n)
{
    double rel[3];
    int k;
    for (k = 0; k < 3; k++) rel[k] = p[k] - v[k];
    switch (kind) {
    case SA_PLANE:
        for (k = 0; k < 3; k++) n[k] = v[3 + k];
        return sa_dot3(rel, v + 3);
    case SA_SPHERE: {
        static const double up[3] = {0.0, 0.0, 1.0};
        sa_unit3(rel, up, n);
        return sa_norm3(rel) - v[3];
    }
    case SA_CYLINDER:
        return sa_cylinder(rel, v + 3, v[6], v[7], n);
    default:
        return sa_box(rel, v + 3, v + 12, n);
    }
}

/* d^n for d > 0, as softarm takes it. */
static double sa_power(double d, double n)
{
    if (n == 1.5) return d * sqrt(d);
    if (n == 1.0) return d;
    if (n == 2.0) return d * d;
    return pow(d, n);
}

/* The normal force at depth d (> 0: penetrating) growing at rate, for a
 * contact that began at normal speed v_in: law = (kind, k, c or n, b or
 * a, friction, slip). Never pulling. */
static double sa_normal_force(const double *law, double d, double rate, double v_in)
{
    double f, k = law[1];
    if (d <= 0.0) return 0.0;
    switch ((int)law[0]) {
    case SA_SPRING_DASHPOT:
        f = d * k + rate * law[2];
        break;
    case SA_HERTZ:
        f = sa_power(d, law[2]) * k;
        break;
    case SA_HC_GIVEN:
        f = sa_power(d, law[2]) * k * (rate * (law[3] / k) + 1.0);
        break;
    default:
        f = sa_power(d, law[2]) * k * (rate * (law[3] / fmax(v_in, 1e-3 /*SLOWEST_IMPACT*/)) + 1.0);
        break;
    }
    return f < 0.0 ? 0.0 : f;
}

/* Friction on a point sliding at v_t under normal force f_n: -mu f_n v_t /
 * sqrt(|v_t|^2 + v_s^2). */
static void sa_friction(const double *law, double f_n, const double *v_t, double *f)
{
    double speed, scale;
    int k;
    if (law[4] == 0.0 || f_n == 0.0) {
        f[0] = f[1] = f[2] = 0.0;
        return;
    }
    speed = sqrt(sa_dot3(v_t, v_t) + law[5] * law[5]);
    scale = f_n * (-law[4]) / speed;
    for (k = 0; k < 3; k++) f[k] = v_t[k] * scale;
}
