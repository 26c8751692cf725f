/* The link recursion (softarm's runtime_kernels::links): a chain's world
 * frame composed link by link from each link's cell, the bodies' inertial
 * and gravity forces, and the wrench past each link projected on its
 * coordinates' twists. One sweep gives tau = M qdd + h and, in dual
 * numbers through the cells' tangents, its directional derivative along
 * (dq, dqd) (links/tangent.rs); M by one sweep carrying all its columns;
 * with LINK_ABA, the accelerations by the articulated-body recursion
 * without M (links/articulated.rs); the outputs and the shape by sweeps
 * over the pose cells (links/outputs.rs). The layout (LINK_*, TERM_*, the
 * base, the tip) is the model's, above. */

typedef struct {
    double v, d;
} sa_dual;
typedef struct {
    sa_dual c[3];
} sa_d3;

static sa_dual sa_dc(double v) { sa_dual r; r.v = v; r.d = 0.0; return r; }
static sa_dual sa_dadd(sa_dual a, sa_dual b) { a.v += b.v; a.d += b.d; return a; }
static sa_dual sa_dsub(sa_dual a, sa_dual b) { a.v -= b.v; a.d -= b.d; return a; }
static sa_dual sa_dmul(sa_dual a, sa_dual b)
{
    sa_dual r;
    r.v = a.v * b.v;
    r.d = a.d * b.v + a.v * b.d;
    return r;
}
static sa_d3 sa_zero3(void) { sa_d3 r; memset(&r, 0, sizeof r); return r; }
static sa_d3 sa_add3(sa_d3 a, sa_d3 b)
{
    int k;
    for (k = 0; k < 3; k++) a.c[k] = sa_dadd(a.c[k], b.c[k]);
    return a;
}
static sa_d3 sa_sub3(sa_d3 a, sa_d3 b)
{
    int k;
    for (k = 0; k < 3; k++) a.c[k] = sa_dsub(a.c[k], b.c[k]);
    return a;
}
static sa_d3 sa_scale3(sa_dual s, sa_d3 a)
{
    int k;
    for (k = 0; k < 3; k++) a.c[k] = sa_dmul(s, a.c[k]);
    return a;
}
static sa_dual sa_ddot(sa_d3 a, sa_d3 b)
{
    return sa_dadd(sa_dadd(sa_dmul(a.c[0], b.c[0]), sa_dmul(a.c[1], b.c[1])), sa_dmul(a.c[2], b.c[2]));
}
static sa_d3 sa_dcross(sa_d3 a, sa_d3 b)
{
    sa_d3 r;
    r.c[0] = sa_dsub(sa_dmul(a.c[1], b.c[2]), sa_dmul(a.c[2], b.c[1]));
    r.c[1] = sa_dsub(sa_dmul(a.c[2], b.c[0]), sa_dmul(a.c[0], b.c[2]));
    r.c[2] = sa_dsub(sa_dmul(a.c[0], b.c[1]), sa_dmul(a.c[1], b.c[0]));
    return r;
}
/* r (rows r[0..3]) times v. */
static sa_d3 sa_dmatvec(const sa_d3 *r, sa_d3 v)
{
    sa_d3 o;
    int k;
    for (k = 0; k < 3; k++) o.c[k] = sa_ddot(r[k], v);
    return o;
}
/* Axisymmetric inertia applied to w. */
static sa_d3 sa_apply_body(sa_dual lateral, sa_dual axial, sa_d3 axis, sa_d3 w)
{
    return sa_add3(sa_scale3(lateral, w), sa_scale3(sa_dmul(sa_dsub(axial, lateral), sa_ddot(axis, w)), axis));
}
/* a + alpha x r + w x (w x r) + 2 w x rate + accel. */
static sa_d3 sa_point_accel(sa_d3 a, sa_d3 alpha, sa_d3 w, sa_d3 r, sa_d3 rate, sa_d3 accel)
{
    return sa_add3(sa_add3(sa_add3(a, sa_dcross(alpha, r)), sa_dcross(w, sa_dcross(w, r))),
                   sa_add3(sa_scale3(sa_dc(2.0), sa_dcross(w, rate)), accel));
}

/* Output i of a cell's tangent (len values, then their derivatives). */
static sa_dual sa_cell_dual(const double *out, size_t len, size_t i)
{
    sa_dual r;
    r.v = out[i];
    r.d = out[len + i];
    return r;
}
static sa_d3 sa_cell_v3(const double *out, size_t len, size_t i)
{
    sa_d3 r;
    int k;
    for (k = 0; k < 3; k++) r.c[k] = sa_cell_dual(out, len, i + (size_t)k);
    return r;
}

/* What the sweep back needs of a link (links/tangent.rs' LinkForces). */
typedef struct {
    sa_d3 centroid, force, torque, axis;
    sa_dual m, lateral, axial;
    sa_d3 twist_w[LINK_MAX_DOF], twist_v[LINK_MAX_DOF], own_w[LINK_MAX_DOF], own_v[LINK_MAX_DOF];
    sa_dual local_force[LINK_MAX_DOF];
} sa_link;

/* Doubles a link's record takes in the workspace. */
#define SA_LINK_DOUBLES ((sizeof(sa_link) + sizeof(double) - 1) / sizeof(double))

/* The workspace LINK_RECORD counts for a record must hold it. */
typedef char sa_link_record_fits[SA_LINK_DOUBLES <= LINK_RECORD ? 1 : -1];

/* The frame a link starts from. */
typedef struct {
    sa_d3 r[3], pos, omega, alpha, acc;
} sa_frame;

/* A link's cell coordinates from the arm's v (each its terms' combination,
 * scaled). */
static void sa_local(size_t k, const double *p, const double *v, double *x)
{
    size_t f, i;
    for (f = 0; f < LINK_MAX_DOF; f++) x[f] = 0.0;
    for (f = 0; f < LINK_DOF[k]; f++) {
        size_t at = LINK_TERMS[k][f];
        double s = 0.0, sc = LINK_SCALE[k][f] < 0 ? 1.0 : p[LINK_SCALE[k][f]];
        for (i = TERM_START[at]; i < TERM_START[at + 1]; i++) s += TERM_WEIGHT[i] * v[TERM_COORD[i]];
        x[f] = sc * s;
    }
}

/* Link k's cell parameters: its element parameters, its segment's
 * actuation loads (zero where none act), its rest strains. */
static void sa_link_params(size_t k, const double *p, const double *loads, double *v)
{
    size_t i;
    for (i = 0; i < LINK_ELEMENT_PARAMS; i++) v[i] = p[LINK_PARAM[k][i]];
    for (i = 0; i < LINK_ACTUATION; i++)
        v[LINK_ELEMENT_PARAMS + i] = LINK_LOAD[k] < 0 ? 0.0 : loads[3 * LINK_LOAD[k] + i];
    for (i = 0; i < LINK_REST_PARAMS; i++)
        v[LINK_ELEMENT_PARAMS + LINK_ACTUATION + i] = p[LINK_PARAM[k][LINK_ELEMENT_PARAMS + i]];
    /* Sections that bend unequally stay on the flat kernels in C. */
    for (i = LINK_ELEMENT_PARAMS + LINK_ACTUATION + LINK_REST_PARAMS; i < LINK_CELL_PARAMS; i++)
        v[i] = 0.0;
}

/* The base frame's rotation (rows) and quaternion. */
static void sa_base(const double *p, double r[3][3], double quat[4])
{
    int i, j;
    if (BASE_ANGLE >= 0) {
        double a = p[BASE_ANGLE], s = sin(a), c = cos(a);
        double rows[3][3] = {{c, -s, 0.0}, {s, c, 0.0}, {0.0, 0.0, 1.0}};
        memcpy(r, rows, sizeof rows);
        quat[0] = cos(0.5 * a);
        quat[1] = quat[2] = 0.0;
        quat[3] = sin(0.5 * a);
        return;
    }
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++) r[i][j] = p[BASE_ROTATION[3 * i + j]];
    for (i = 0; i < 4; i++) quat[i] = p[BASE_QUATERNION[i]];
}

/* One link of the sweep out (links/tangent.rs' link_forward). */
static void sa_link_forward(sa_frame *frame, const double *out, size_t nc, const double *xdd,
                            const sa_dual *inertia_rates, sa_d3 gravity, sa_link *l)
{
    size_t len = LINK_CELL_LEN(nc), f;
    sa_d3 rel[3], d, dd, cen, cend, w_rel, w_b, axis, ddd, w_rel_d, cendd, w_b_d, end, body_a, body_w,
        body_alpha, iw, torque;
    sa_dual m = sa_cell_dual(out, len, LINK_MASS), lateral = sa_cell_dual(out, len, LINK_MASS + 1),
            axial = sa_cell_dual(out, len, LINK_MASS + 2);
    sa_frame f0 = *frame;
    int i;
    for (i = 0; i < 3; i++) rel[i] = sa_cell_v3(out, len, LINK_ROTATION + 3 * (size_t)i);
#define TURN(at) sa_dmatvec(f0.r, sa_cell_v3(out, len, (at)))
    d = TURN(LINK_END);
    dd = TURN(LINK_END + 3);
    cen = TURN(LINK_CENTROID);
    cend = TURN(LINK_CENTROID + 3);
    w_rel = TURN(LINK_OMEGA);
    w_b = TURN(LINK_BODY_OMEGA);
    axis = TURN(LINK_AXIS);
    ddd = TURN(LINK_END + 6);
    w_rel_d = TURN(LINK_OMEGA + 3);
    cendd = TURN(LINK_CENTROID + 6);
    w_b_d = TURN(LINK_BODY_OMEGA + 3);
    end = sa_add3(f0.pos, d);
    for (f = 0; f < LINK_MAX_DOF; f++) {
        l->twist_w[f] = l->twist_v[f] = l->own_w[f] = l->own_v[f] = sa_zero3();
        l->local_force[f] = sa_dc(0.0);
    }
    for (f = 0; f < nc; f++) {
        size_t col = LINK_COLUMNS + 12 * f;
        sa_d3 s_w = TURN(col), v_end = TURN(col + 3);
        sa_dual a = sa_dc(xdd[f]);
        ddd = sa_add3(ddd, sa_scale3(a, v_end));
        w_rel_d = sa_add3(w_rel_d, sa_scale3(a, s_w));
        cendd = sa_add3(cendd, sa_scale3(a, TURN(col + 9)));
        w_b_d = sa_add3(w_b_d, sa_scale3(a, TURN(col + 6)));
        l->twist_w[f] = s_w;
        l->twist_v[f] = sa_sub3(v_end, sa_dcross(s_w, end));
        l->own_w[f] = TURN(col + 6);
        l->own_v[f] = TURN(col + 9);
        l->local_force[f] = sa_cell_dual(out, len, LINK_COLUMNS + 12 * nc + f);
    }
#undef TURN
    body_a = sa_point_accel(f0.acc, f0.alpha, f0.omega, cen, cend, cendd);
    body_w = sa_add3(f0.omega, w_b);
    body_alpha = sa_add3(sa_add3(f0.alpha, sa_dcross(f0.omega, w_b)), w_b_d);
    iw = sa_apply_body(lateral, axial, axis, body_w);
    torque = sa_add3(sa_apply_body(lateral, axial, axis, body_alpha), sa_dcross(body_w, iw));
    if (inertia_rates) {
        /* The torque I' w and -|w|^2 dI/dx / 2 of an inertia that changes. */
        sa_dual i_dot = sa_dc(0.0), half_w2 = sa_dmul(sa_dc(0.5), sa_ddot(body_w, body_w));
        size_t rates = LINK_COLUMNS + 13 * nc;
        for (f = 0; f < nc; f++) i_dot = sa_dadd(i_dot, sa_dmul(sa_cell_dual(out, len, rates + f), inertia_rates[f]));
        torque = sa_add3(torque, sa_scale3(i_dot, body_w));
        for (f = 0; f < nc; f++)
            l->local_force[f] = sa_dsub(l->local_force[f], sa_dmul(half_w2, sa_cell_dual(out, len, rates + f)));
    }
    l->centroid = sa_add3(f0.pos, cen);
    l->axis = axis;
    l->m = m;
    l->lateral = lateral;
    l->axial = axial;
    l->force = sa_scale3(m, sa_sub3(body_a, gravity));
    l->torque = torque;
    for (i = 0; i < 3; i++) {
        sa_d3 col;
        int j;
        for (j = 0; j < 3; j++) col.c[j] = rel[j].c[i];
        for (j = 0; j < 3; j++) frame->r[j].c[i] = sa_ddot(f0.r[j], col);
    }
    frame->pos = end;
    frame->omega = sa_add3(f0.omega, w_rel);
    frame->alpha = sa_add3(sa_add3(f0.alpha, sa_dcross(f0.omega, w_rel)), w_rel_d);
    frame->acc = sa_point_accel(f0.acc, f0.alpha, f0.omega, d, dd, ddd);
}

/* The wrench (moment about the world origin, force) of what hangs on the
 * end frame: the tip body's inertial and gravity forces and the tip loads,
 * as forces of the opposite sign (links/tangent.rs' tip_wrench). */
static void sa_tip_wrench(const sa_frame *fr, const double *p, sa_d3 gravity, sa_d3 *moment, sa_d3 *force)
{
    sa_d3 axis, point, tip_f = sa_zero3(), tip_m = sa_zero3();
    sa_dual length = sa_dc(TIP_LENGTH < 0 ? 0.0 : p[TIP_LENGTH]);
    int k;
    for (k = 0; k < 3; k++) axis.c[k] = fr->r[k].c[0];
    point = sa_add3(fr->pos, sa_scale3(length, axis));
    *moment = *force = sa_zero3();
    if (TIP_MASS >= 0) {
        sa_dual m = sa_dc(p[TIP_MASS]);
        sa_d3 offset = sa_scale3(sa_dmul(sa_dc(0.5), length), axis), centre = sa_add3(fr->pos, offset);
        sa_dual lateral = sa_dc(TIP_LATERAL < 0 ? 0.0 : p[TIP_LATERAL]);
        sa_dual axial = sa_dc(TIP_AXIAL < 0 ? 0.0 : p[TIP_AXIAL]);
        sa_d3 a_c = sa_point_accel(fr->acc, fr->alpha, fr->omega, offset, sa_zero3(), sa_zero3());
        sa_d3 iw = sa_apply_body(lateral, axial, axis, fr->omega), torque;
        *force = sa_scale3(m, sa_sub3(a_c, gravity));
        torque = sa_add3(sa_apply_body(lateral, axial, axis, fr->alpha), sa_dcross(fr->omega, iw));
        *moment = sa_add3(torque, sa_dcross(centre, *force));
    }
    for (k = 0; k < 3; k++) {
        if (TIP_FORCE[k] >= 0) tip_f.c[k] = sa_dc(-p[TIP_FORCE[k]]);
        if (TIP_MOMENT[k] >= 0) tip_m.c[k] = sa_dc(-p[TIP_MOMENT[k]]);
    }
    if (TIP_FRAME) {
        tip_f = sa_dmatvec(fr->r, tip_f);
        tip_m = sa_dmatvec(fr->r, tip_m);
    }
    *moment = sa_add3(*moment, sa_add3(sa_dcross(point, tip_f), tip_m));
    *force = sa_add3(*force, tip_f);
}

/* Every link's cell at (q, qd) with its derivatives along dir = (dq, dqd)
 * into cells (2 LINK_CELL_LEN(LINK_MAX_DOF) values a link): a link the
 * direction does not move takes its value cell and zero derivatives.
 * w: the loads, then the cells' scratch. */
static void links_cells(double t, const double *q, const double *qd, const double *dir, const double *p,
                        double *cells, double *w)
{
    double *loads = w, *scratch = loads + 3 * LINK_LOADS + 1;
    double cp[LINK_CELL_PARAMS], x[LINK_MAX_DOF], xd[LINK_MAX_DOF], dq[LINK_MAX_DOF], dqd[LINK_MAX_DOF];
    double dx[2 * LINK_MAX_DOF];
    size_t k, i;
    links_loads(t, q, qd, p, loads, scratch);
    for (k = 0; k < LINK_COUNT; k++) {
        size_t nc = LINK_DOF[k], len = LINK_CELL_LEN(nc);
        double *out = cells + k * 2 * LINK_CELL_LEN(LINK_MAX_DOF);
        int moves = 0;
        sa_link_params(k, p, loads, cp);
        sa_local(k, p, q, x);
        sa_local(k, p, qd, xd);
        sa_local(k, p, dir, dq);
        sa_local(k, p, dir + NQ_LINKS, dqd);
        for (i = 0; i < nc; i++) {
            dx[i] = dq[i];
            dx[nc + i] = dqd[i];
            moves |= dq[i] != 0.0 || dqd[i] != 0.0;
        }
        if (moves) {
            cell_tangent(LINK_CELL[k], x, xd, dx, cp, out, scratch);
        } else {
            cell_one(LINK_CELL[k], x, xd, cp, out, scratch);
            memset(out + len, 0, len * sizeof(double));
        }
    }
}

/* The sweep out at qdd from the cells `links_cells` gave: each link's
 * record into links, the end frame into *end, gravity into *gravity. */
static void links_forward(const double *qd, const double *qdd, const double *dir, const double *p,
                          const double *cells, double *links, sa_frame *end, sa_d3 *gravity)
{
    double xdd[LINK_MAX_DOF], xd[LINK_MAX_DOF], dqd[LINK_MAX_DOF], base[3][3], quat[4];
    size_t k, i, c;
    for (i = 0; i < 3; i++) gravity->c[i] = sa_dc(p[GRAVITY[i]]);
    sa_base(p, base, quat);
    for (i = 0; i < 3; i++) {
        for (c = 0; c < 3; c++) end->r[i].c[c] = sa_dc(base[i][c]);
        end->pos.c[i] = sa_dc(p[BASE_POSITION[i]]);
    }
    end->omega = end->alpha = end->acc = sa_zero3();
    for (k = 0; k < LINK_COUNT; k++) {
        size_t nc = LINK_DOF[k];
        sa_dual rates[LINK_MAX_DOF];
        sa_link l;
        sa_local(k, p, qdd, xdd);
        if (VARIABLE_INERTIA) {
            sa_local(k, p, qd, xd);
            sa_local(k, p, dir + NQ_LINKS, dqd);
            for (i = 0; i < nc; i++) {
                rates[i].v = xd[i];
                rates[i].d = dqd[i];
            }
        }
        sa_link_forward(end, cells + k * 2 * LINK_CELL_LEN(LINK_MAX_DOF), nc, xdd, VARIABLE_INERTIA ? rates : NULL,
                        *gravity, &l);
        memcpy(links + k * SA_LINK_DOUBLES, &l, sizeof l);
    }
}

/* tau = M qdd + h into tau and its derivative along dir into dtau from
 * the cells `links_cells` gave at (q, qd, dir) (links/tangent.rs'
 * inverse_dynamics_tangent). w: the links' records, then the non-local
 * forces and the kernels' scratch. */
static void links_sweep(double t, const double *q, const double *qd, const double *qdd, const double *dir,
                        const double *p, const double *cells, double *tau, double *dtau, double *w)
{
    /* Each link's record, copied in and out (the workspace is doubles). */
    double *links = w, *f = links + LINK_COUNT * SA_LINK_DOUBLES, *scratch = f + 2 * NQ_LINKS;
    sa_frame frame;
    sa_d3 gravity, moment, force;
    sa_dual t_acc[NQ_LINKS];
    size_t k, i;
    links_forward(qd, qdd, dir, p, cells, links, &frame, &gravity);
    sa_tip_wrench(&frame, p, gravity, &moment, &force);
    for (i = 0; i < NQ_LINKS; i++) t_acc[i] = sa_dc(0.0);
    for (k = LINK_COUNT; k-- > 0;) {
        sa_link link;
        const sa_link *l = &link;
        size_t fi;
        memcpy(&link, links + k * SA_LINK_DOUBLES, sizeof link);
        for (fi = 0; fi < LINK_DOF[k]; fi++) {
            size_t at = LINK_TERMS[k][fi];
            sa_dual g = sa_dadd(sa_dadd(sa_dadd(sa_dadd(sa_ddot(l->twist_w[fi], moment), sa_ddot(l->twist_v[fi], force)),
                                                sa_ddot(l->own_v[fi], l->force)),
                                        sa_ddot(l->own_w[fi], l->torque)),
                                l->local_force[fi]);
            double sc = LINK_SCALE[k][fi] < 0 ? 1.0 : p[LINK_SCALE[k][fi]];
            for (i = TERM_START[at]; i < TERM_START[at + 1]; i++)
                t_acc[TERM_COORD[i]] = sa_dadd(t_acc[TERM_COORD[i]], sa_dmul(sa_dc(sc * TERM_WEIGHT[i]), g));
        }
        moment = sa_add3(moment, sa_add3(l->torque, sa_dcross(l->centroid, l->force)));
        force = sa_add3(force, l->force);
    }
    for (i = 0; i < NQ_LINKS; i++) {
        tau[i] = t_acc[i].v;
        dtau[i] = t_acc[i].d;
    }
    if (LINK_FORCES) {
        links_forces_tangent(t, q, qd, qdd, dir, p, f, scratch);
        for (i = 0; i < NQ_LINKS; i++) {
            tau[i] += f[i];
            dtau[i] += f[NQ_LINKS + i];
        }
    }
}

/* The Hamilton product a b (w, x, y, z) into o. */
static void sa_quat_mul(const double *a, const double *b, double *o)
{
    o[0] = a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3];
    o[1] = a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2];
    o[2] = a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1];
    o[3] = a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0];
}
static double sa_dot(const double *a, const double *b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
static void sa_cross(const double *a, const double *b, double *o)
{
    o[0] = a[1] * b[2] - a[2] * b[1];
    o[1] = a[2] * b[0] - a[0] * b[2];
    o[2] = a[0] * b[1] - a[1] * b[0];
}
/* r (rows) times v into o. */
static void sa_turn(double r[3][3], const double *v, double *o)
{
    int i;
    for (i = 0; i < 3; i++) o[i] = sa_dot(r[i], v);
}
/* r <- r rel, rel the 3 x 3 rows at `rows` (a cell's relative rotation). */
static void sa_compose(double r[3][3], const double *rows)
{
    double next[3][3];
    int i, j;
    for (i = 0; i < 3; i++)
        for (j = 0; j < 3; j++) next[i][j] = r[i][0] * rows[j] + r[i][1] * rows[3 + j] + r[i][2] * rows[6 + j];
    memcpy(r, next, sizeof next);
}

/* Kinetic energy of a body of mass m, axisymmetric inertia about axis,
 * moving at (v, w). */
static double sa_kinetic(double m, double lateral, double axial, const double *axis, const double *v,
                         const double *w)
{
    double aw = sa_dot(axis, w), iw[3];
    int k;
    for (k = 0; k < 3; k++) iw[k] = lateral * w[k] + (axial - lateral) * aw * axis[k];
    return 0.5 * (m * sa_dot(v, v) + sa_dot(w, iw));
}

/* Tip position, kinetic and potential energy, tip quaternion by a sweep
 * over the pose cells (links/outputs.rs). */
static void links_outputs(double t, const double *q, const double *qd, const double *p, double *out,
                          double *w)
{
    double *loads = w, *o = loads + 3 * LINK_LOADS + 1, *scratch = o + LINK_POSE_LEN;
    double r[3][3], quat[4], pos[3], v[3] = {0.0, 0.0, 0.0}, omega[3] = {0.0, 0.0, 0.0}, ke = 0.0, pe = 0.0;
    double gravity[3], cp[LINK_CELL_PARAMS], x[LINK_MAX_DOF], xd[LINK_MAX_DOF], axis[3], point[3], length;
    size_t k;
    int i;
    for (i = 0; i < 3; i++) {
        gravity[i] = p[GRAVITY[i]];
        pos[i] = p[BASE_POSITION[i]];
    }
    sa_base(p, r, quat);
    links_loads(t, q, qd, p, loads, scratch);
    for (k = 0; k < LINK_COUNT; k++) {
        double d[3], dd[3], w_rel[3], cen[3], cend[3], w_b[3], ax[3], body_v[3], body_w[3], c1[3], q2[4], m;
        sa_link_params(k, p, loads, cp);
        sa_local(k, p, q, x);
        sa_local(k, p, qd, xd);
        cell_pose(LINK_CELL[k], x, xd, cp, o, scratch);
        sa_turn(r, o + POSE_END, d);
        sa_turn(r, o + POSE_END + 3, dd);
        sa_turn(r, o + POSE_OMEGA, w_rel);
        sa_turn(r, o + POSE_CENTROID, cen);
        sa_turn(r, o + POSE_CENTROID + 3, cend);
        sa_turn(r, o + POSE_BODY_OMEGA, w_b);
        sa_turn(r, o + POSE_AXIS, ax);
        m = o[POSE_MASS];
        sa_cross(omega, cen, c1);
        for (i = 0; i < 3; i++) {
            body_v[i] = v[i] + c1[i] + cend[i];
            body_w[i] = omega[i] + w_b[i];
            c1[i] = pos[i] + cen[i];
        }
        ke += sa_kinetic(m, o[POSE_MASS + 1], o[POSE_MASS + 2], ax, body_v, body_w);
        pe += o[POSE_ENERGY] - m * sa_dot(gravity, c1);
        sa_cross(omega, d, c1);
        for (i = 0; i < 3; i++) {
            v[i] = v[i] + c1[i] + dd[i];
            omega[i] += w_rel[i];
            pos[i] += d[i];
        }
        sa_compose(r, o + POSE_ROTATION);
        sa_quat_mul(quat, o + POSE_QUAT, q2);
        memcpy(quat, q2, sizeof q2);
    }
    for (i = 0; i < 3; i++) axis[i] = r[i][0];
    length = TIP_LENGTH < 0 ? 0.0 : p[TIP_LENGTH];
    if (TIP_MASS >= 0) {
        double m = p[TIP_MASS], offset[3], v_c[3], c1[3], at[3];
        double lateral = TIP_LATERAL < 0 ? 0.0 : p[TIP_LATERAL], axial = TIP_AXIAL < 0 ? 0.0 : p[TIP_AXIAL];
        for (i = 0; i < 3; i++) offset[i] = 0.5 * length * axis[i];
        sa_cross(omega, offset, c1);
        for (i = 0; i < 3; i++) {
            v_c[i] = v[i] + c1[i];
            at[i] = pos[i] + offset[i];
        }
        ke += sa_kinetic(m, lateral, axial, axis, v_c, omega);
        pe -= m * sa_dot(gravity, at);
    }
    for (i = 0; i < 3; i++) point[i] = pos[i] + length * axis[i];
    if (TIP_FORCE[0] >= 0 && !TIP_FRAME) {
        double f[3];
        for (i = 0; i < 3; i++) f[i] = p[TIP_FORCE[i]];
        pe -= sa_dot(f, point);
    }
    if (LINK_FORCES) pe += links_energy(t, q, qd, p, scratch);
    for (i = 0; i < 3; i++) out[i] = point[i];
    out[3] = ke;
    out[4] = pe;
    for (i = 0; i < 4; i++) out[5 + i] = quat[i];
}

/* Per link: its centroid, its end, and its coordinates' columns (the end
 * frame's angular and end point velocity, the body's angular and centroid
 * velocity, then the linear part of the twist at the world origin), in
 * the world frame. */
#define SA_GEOMETRY (6 + 15 * LINK_MAX_DOF)

/* M, all its columns in one sweep (the composite bodies' sums of
 * links/mod.rs in another order): at qd = 0 every velocity vanishes and
 * the accelerations are linear in qdd, so each frame's angular and linear
 * acceleration is carried for every unit qdd_j at once (NQ_LINKS columns),
 * from the cells' frames, columns and inertia (`links_cells`: the rates
 * change none of them), and the wrench past each link
 * projected on its coordinates' twists gives column j of M. Into the
 * packed upper triangle `out`. w: per link its centroid and columns, then
 * each column's force and torque. */
static void links_mass(const double *p, const double *cells, double *out, double *w)
{
    double *geometry = w, *acc = geometry + LINK_COUNT * SA_GEOMETRY;
    double *alpha = acc + 3 * NQ_LINKS, *forces = alpha + 3 * NQ_LINKS;
    double *moment = forces + LINK_COUNT * 6 * NQ_LINKS, *force = moment + 3 * NQ_LINKS;
    double *tau = force + 3 * NQ_LINKS;
    double r[3][3], quat[4], pos[3];
    size_t k, j, f, i;
    int a;
    sa_base(p, r, quat);
    for (a = 0; a < 3; a++) pos[a] = p[BASE_POSITION[a]];
    memset(acc, 0, 6 * NQ_LINKS * sizeof(double));
    for (k = 0; k < LINK_COUNT; k++) {
        size_t nc = LINK_DOF[k], len = LINK_CELL_LEN(nc);
        const double *o = cells + k * 2 * LINK_CELL_LEN(LINK_MAX_DOF);
        double *g = geometry + k * SA_GEOMETRY, d[3], cen[3], axis[3];
        double xdd[LINK_MAX_DOF][NQ_LINKS + 1], m = o[LINK_MASS], lateral = o[LINK_MASS + 1],
                                                axial = o[LINK_MASS + 2];
        (void)len;
        sa_turn(r, o + LINK_END, d);
        sa_turn(r, o + LINK_CENTROID, cen);
        sa_turn(r, o + LINK_AXIS, axis);
        for (a = 0; a < 3; a++) {
            g[a] = pos[a] + cen[a];
            g[3 + a] = pos[a] + d[a];
        }
        for (f = 0; f < nc; f++) {
            double *col = g + 6 + 15 * f, c1[3];
            for (i = 0; i < 4; i++) sa_turn(r, o + LINK_COLUMNS + 12 * f + 3 * i, col + 3 * i);
            /* v_end - s_w x end. */
            sa_cross(col, g + 3, c1);
            for (a = 0; a < 3; a++) col[12 + a] = col[3 + a] - c1[a];
        }
        /* Cell coordinate f's acceleration for each unit qdd_j. */
        for (f = 0; f < nc; f++) {
            size_t at = LINK_TERMS[k][f];
            double sc = LINK_SCALE[k][f] < 0 ? 1.0 : p[LINK_SCALE[k][f]];
            for (j = 0; j < NQ_LINKS; j++) xdd[f][j] = 0.0;
            for (i = TERM_START[at]; i < TERM_START[at + 1]; i++) xdd[f][TERM_COORD[i]] += sc * TERM_WEIGHT[i];
        }
        for (j = 0; j < NQ_LINKS; j++) {
            double *aj = acc + 3 * j, *alj = alpha + 3 * j, *fj = forces + (k * NQ_LINKS + j) * 6;
            double body_a[3], body_alpha[3], c1[3], ddd[3] = {0.0, 0.0, 0.0}, w_rel_d[3] = {0.0, 0.0, 0.0};
            double aw;
            /* Before the first link coordinate j moves, nothing accelerates. */
            if (k < COORD_FIRST_LINK[j]) continue;
            sa_cross(alj, cen, c1);
            for (a = 0; a < 3; a++) {
                body_a[a] = aj[a] + c1[a];
                body_alpha[a] = alj[a];
            }
            for (f = 0; f < nc; f++) {
                const double *col = g + 6 + 15 * f;
                for (a = 0; a < 3; a++) {
                    ddd[a] += xdd[f][j] * col[3 + a];
                    w_rel_d[a] += xdd[f][j] * col[a];
                    body_alpha[a] += xdd[f][j] * col[6 + a];
                    body_a[a] += xdd[f][j] * col[9 + a];
                }
            }
            aw = sa_dot(axis, body_alpha);
            for (a = 0; a < 3; a++) {
                fj[a] = m * body_a[a];
                fj[3 + a] = lateral * body_alpha[a] + (axial - lateral) * aw * axis[a];
            }
            /* The end frame's accelerations. */
            sa_cross(alj, d, c1);
            for (a = 0; a < 3; a++) {
                aj[a] += c1[a] + ddd[a];
                alj[a] += w_rel_d[a];
            }
        }
        sa_compose(r, o + LINK_ROTATION);
        for (a = 0; a < 3; a++) pos[a] += d[a];
    }
    /* The tip body's wrench for each column. */
    memset(moment, 0, 6 * NQ_LINKS * sizeof(double));
    if (TIP_MASS >= 0) {
        double m = p[TIP_MASS], length = TIP_LENGTH < 0 ? 0.0 : p[TIP_LENGTH], axis[3], offset[3], centre[3];
        double lateral = TIP_LATERAL < 0 ? 0.0 : p[TIP_LATERAL], axial = TIP_AXIAL < 0 ? 0.0 : p[TIP_AXIAL];
        for (a = 0; a < 3; a++) {
            axis[a] = r[a][0];
            offset[a] = 0.5 * length * axis[a];
            centre[a] = pos[a] + offset[a];
        }
        for (j = 0; j < NQ_LINKS; j++) {
            double c1[3], torque[3], aw = sa_dot(axis, alpha + 3 * j);
            sa_cross(alpha + 3 * j, offset, c1);
            for (a = 0; a < 3; a++) {
                force[3 * j + a] = m * (acc[3 * j + a] + c1[a]);
                torque[a] = lateral * alpha[3 * j + a] + (axial - lateral) * aw * axis[a];
            }
            sa_cross(centre, force + 3 * j, c1);
            for (a = 0; a < 3; a++) moment[3 * j + a] = torque[a] + c1[a];
        }
    }
    /* Back from the tip: column j's wrench past each link on its twists,
     * down to the first link coordinate j moves: the rows of coordinates
     * no earlier link moves are complete (the others come by symmetry). */
    memset(tau, 0, NQ_LINKS * NQ_LINKS * sizeof(double));
    for (k = LINK_COUNT; k-- > 0;) {
        const double *g = geometry + k * SA_GEOMETRY;
        for (j = 0; j < NQ_LINKS; j++) {
            const double *fj = forces + (k * NQ_LINKS + j) * 6;
            double *mj = moment + 3 * j, *Fj = force + 3 * j, c1[3];
            if (k < COORD_FIRST_LINK[j]) continue;
            for (f = 0; f < LINK_DOF[k]; f++) {
                const double *col = g + 6 + 15 * f;
                size_t at = LINK_TERMS[k][f];
                double sc = LINK_SCALE[k][f] < 0 ? 1.0 : p[LINK_SCALE[k][f]];
                double gf = sa_dot(col, mj) + sa_dot(col + 12, Fj) + sa_dot(col + 9, fj) + sa_dot(col + 6, fj + 3);
                for (i = TERM_START[at]; i < TERM_START[at + 1]; i++)
                    tau[j * NQ_LINKS + TERM_COORD[i]] += sc * TERM_WEIGHT[i] * gf;
            }
            sa_cross(g, fj, c1);
            for (a = 0; a < 3; a++) {
                mj[a] += fj[3 + a] + c1[a];
                Fj[a] += fj[a];
            }
        }
    }
    for (j = 0; j < NQ_LINKS; j++)
        for (i = 0; i <= j; i++)
            out[sa_packed(NQ_LINKS, i, j)] =
                COORD_FIRST_LINK[j] >= COORD_FIRST_LINK[i] ? tau[i * NQ_LINKS + j] : tau[j * NQ_LINKS + i];
}

/* The kernels the library calls, on the recursion. M qdd + h packed from
 * the cells at (q, qd): h at qdd = 0, and M, which reads only what of the
 * cells the rates do not change (frames, columns, inertia). */
#define SA_CELLS (LINK_COUNT * 2 * LINK_CELL_LEN(LINK_MAX_DOF))
static void k_mass_bias(double t, const double *q, const double *qd, const double *qdd, const double *dir,
                        const double *p, const double *aux, double *out, double *scratch)
{
    double *zero = scratch, *dtau = zero + 2 * NQ_LINKS, *cells = dtau + NQ_LINKS, *w = cells + SA_CELLS;
    (void)qdd; (void)dir; (void)aux;
    memset(zero, 0, 2 * NQ_LINKS * sizeof(double));
    links_cells(t, q, qd, zero, p, cells, w);
    links_sweep(t, q, qd, zero, zero, p, cells, out + NQ_LINKS * (NQ_LINKS + 1) / 2, dtau, w);
    links_mass(p, cells, out, w);
}

/* The directional derivative of tau = M qdd + h along dir = (dq, dqd). */
static void k_jvp(double t, const double *q, const double *qd, const double *qdd, const double *dir,
                  const double *p, const double *aux, double *out, double *scratch)
{
    double *tau = scratch, *cells = tau + NQ_LINKS, *w = cells + SA_CELLS;
    (void)aux;
    links_cells(t, q, qd, dir, p, cells, w);
    links_sweep(t, q, qd, qdd, dir, p, cells, tau, out, w);
}

#if LINK_ABA
/* The articulated-body recursion of a chain whose links own their
 * coordinates (links/articulated.rs): qdd = -M^-1 h without M, each link
 * eliminating its own coordinates from the tip, then the accelerations
 * from the base. Twists (w, v at the world origin) and wrenches (moment
 * about the origin, force) as six values. */

/* A spatial inertia about the world origin: mass, first moment, J (xx,
 * yy, zz, xy, xz, yz). */
typedef struct {
    double m, h[3], j[6];
} sa_inertia;

static void sa_add_body(sa_inertia *in, double m, const double *r, double lateral, double axial, const double *axis)
{
    static const int pa[6] = {0, 1, 2, 0, 0, 1}, pb[6] = {0, 1, 2, 1, 2, 2};
    double r2 = sa_dot(r, r), d = axial - lateral, diag = lateral + m * r2;
    int k;
    in->m += m;
    for (k = 0; k < 3; k++) in->h[k] += m * r[k];
    for (k = 0; k < 6; k++)
        in->j[k] += (k < 3 ? diag : 0.0) + d * axis[pa[k]] * axis[pb[k]] - m * r[pa[k]] * r[pb[k]];
}

/* The momentum of the twist tw: (J w + h x v, m v + w x h). */
static void sa_momentum(const sa_inertia *in, const double *tw, double *out)
{
    const double *j = in->j, *w = tw, *v = tw + 3;
    double c1[3], c2[3];
    int k;
    sa_cross(in->h, v, c1);
    sa_cross(w, in->h, c2);
    out[0] = j[0] * w[0] + j[3] * w[1] + j[4] * w[2] + c1[0];
    out[1] = j[3] * w[0] + j[1] * w[1] + j[5] * w[2] + c1[1];
    out[2] = j[4] * w[0] + j[5] * w[1] + j[2] * w[2] + c1[2];
    for (k = 0; k < 3; k++) out[3 + k] = in->m * v[k] + c2[k];
}

/* Its 6 x 6 matrix. */
static void sa_inertia_matrix(const sa_inertia *in, double a[6][6])
{
    int c, k;
    for (c = 0; c < 6; c++) {
        double e[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0}, col[6];
        e[c] = 1.0;
        sa_momentum(in, e, col);
        for (k = 0; k < 6; k++) a[k][c] = col[k];
    }
}

static double sa_dot6(const double *a, const double *b)
{
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3] + a[4] * b[4] + a[5] * b[5];
}

/* L D L^T of the n x n lower triangle of d in place; 0 unless positive
 * definite. */
static int sa_factor_small(double d[LINK_MAX_DOF][LINK_MAX_DOF], size_t n)
{
    size_t i, j, k;
    for (j = 0; j < n; j++) {
        double p = d[j][j];
        for (k = 0; k < j; k++) p -= d[j][k] * d[j][k] * d[k][k];
        if (!(p > 0.0)) return 0;
        d[j][j] = p;
        for (i = j + 1; i < n; i++) {
            double s = d[i][j];
            for (k = 0; k < j; k++) s -= d[i][k] * d[j][k] * d[k][k];
            d[i][j] = s / p;
        }
    }
    return 1;
}

/* x = D^-1 x in place by sa_factor_small's factors. */
static void sa_solve_small(double d[LINK_MAX_DOF][LINK_MAX_DOF], size_t n, double *x)
{
    size_t i, k;
    for (i = 0; i < n; i++)
        for (k = 0; k < i; k++) x[i] -= d[i][k] * x[k];
    for (i = 0; i < n; i++) x[i] /= d[i][i];
    for (i = n; i-- > 0;)
        for (k = i + 1; k < n; k++) x[i] -= d[k][i] * x[k];
}

/* What the sweep from the tip keeps of a link for the sweep from the base. */
typedef struct {
    double s_e[LINK_MAX_DOF][6], u_cols[LINK_MAX_DOF][6], d[LINK_MAX_DOF][LINK_MAX_DOF], u[LINK_MAX_DOF];
} sa_eliminated;
#define SA_ELIMINATED_DOUBLES ((sizeof(sa_eliminated) + sizeof(double) - 1) / sizeof(double))

/* qdd = -M^-1 h at (q, qd); 0 unless every link's D is positive definite
 * (M is then too). w: LINKS_ABA_WORK values. */
static int links_accelerations(double t, const double *q, const double *qd, const double *p, double *qdd,
                               double *w)
{
    double *zero = w, *cells = zero + 2 * NQ_LINKS, *links = cells + SA_CELLS;
    double *kept = links + LINK_COUNT * SA_LINK_DOUBLES, *scratch = kept + LINK_COUNT * SA_ELIMINATED_DOUBLES;
    double ia[6][6], pa[6], a[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    sa_inertia past;
    sa_frame end;
    sa_d3 gravity, moment, force;
    size_t k, f, f2, i, j, at;
    memset(zero, 0, 2 * NQ_LINKS * sizeof(double));
    memset(&past, 0, sizeof past);
    links_cells(t, q, qd, zero, p, cells, scratch);
    links_forward(qd, zero, zero, p, cells, links, &end, &gravity);
    sa_tip_wrench(&end, p, gravity, &moment, &force);
    if (TIP_MASS >= 0) {
        double length = TIP_LENGTH < 0 ? 0.0 : p[TIP_LENGTH], axis[3], centre[3];
        for (i = 0; i < 3; i++) {
            axis[i] = end.r[i].c[0].v;
            centre[i] = end.pos.c[i].v + 0.5 * length * axis[i];
        }
        sa_add_body(&past, p[TIP_MASS], centre, TIP_LATERAL < 0 ? 0.0 : p[TIP_LATERAL],
                    TIP_AXIAL < 0 ? 0.0 : p[TIP_AXIAL], axis);
    }
    sa_inertia_matrix(&past, ia);
    for (i = 0; i < 3; i++) {
        pa[i] = moment.c[i].v;
        pa[3 + i] = force.c[i].v;
    }
    for (k = LINK_COUNT; k-- > 0;) {
        size_t nc = LINK_DOF[k];
        sa_link l;
        sa_eliminated e;
        sa_inertia body;
        double ib[6][6], fb[6], s_b[LINK_MAX_DOF][6], ib_sb[LINK_MAX_DOF][6], ia_se[LINK_MAX_DOF][6];
        double wm[LINK_MAX_DOF][6], cen[3], axis[3], c1[3];
        memcpy(&l, links + k * SA_LINK_DOUBLES, sizeof l);
        memset(&e, 0, sizeof e);
        memset(&body, 0, sizeof body);
        for (i = 0; i < 3; i++) {
            cen[i] = l.centroid.c[i].v;
            axis[i] = l.axis.c[i].v;
        }
        sa_add_body(&body, l.m.v, cen, l.lateral.v, l.axial.v, axis);
        sa_inertia_matrix(&body, ib);
        for (i = 0; i < 3; i++) {
            double fv[3] = {l.force.c[0].v, l.force.c[1].v, l.force.c[2].v};
            sa_cross(cen, fv, c1);
            fb[i] = l.torque.c[i].v + c1[i];
            fb[3 + i] = fv[i];
        }
        for (f = 0; f < nc; f++) {
            double ow[3], ov[3];
            for (i = 0; i < 3; i++) {
                ow[i] = l.own_w[f].c[i].v;
                ov[i] = l.own_v[f].c[i].v;
            }
            /* The body's column as a twist about the origin. */
            sa_cross(ow, cen, c1);
            for (i = 0; i < 3; i++) {
                s_b[f][i] = ow[i];
                s_b[f][3 + i] = ov[i] - c1[i];
                e.s_e[f][i] = l.twist_w[f].c[i].v;
                e.s_e[f][3 + i] = l.twist_v[f].c[i].v;
            }
            sa_momentum(&body, s_b[f], ib_sb[f]);
            for (i = 0; i < 6; i++) ia_se[f][i] = sa_dot6(ia[i], e.s_e[f]);
            for (i = 0; i < 6; i++) e.u_cols[f][i] = ib_sb[f][i] + ia_se[f][i];
            e.u[f] = sa_dot6(s_b[f], fb) + sa_dot6(e.s_e[f], pa) + l.local_force[f].v;
        }
        for (f = 0; f < nc; f++)
            for (f2 = 0; f2 <= f; f2++) e.d[f][f2] = sa_dot6(s_b[f], ib_sb[f2]) + sa_dot6(e.s_e[f], ia_se[f2]);
        if (!sa_factor_small(e.d, nc)) return 0;
        /* IA <- I_b + IA - U D^-1 U^T, pA <- F_b + pA - U D^-1 u. */
        for (i = 0; i < 6; i++) {
            double row[LINK_MAX_DOF];
            for (f = 0; f < nc; f++) row[f] = e.u_cols[f][i];
            sa_solve_small(e.d, nc, row);
            for (f = 0; f < nc; f++) wm[f][i] = row[f];
        }
        for (i = 0; i < 6; i++) {
            double v;
            for (j = i; j < 6; j++) {
                v = ib[i][j] + ia[i][j];
                for (f = 0; f < nc; f++) v -= e.u_cols[f][i] * wm[f][j];
                ia[i][j] = ia[j][i] = v;
            }
            v = fb[i] + pa[i];
            for (f = 0; f < nc; f++) v -= wm[f][i] * e.u[f];
            pa[i] = v;
        }
        memcpy(kept + k * SA_ELIMINATED_DOUBLES, &e, sizeof e);
    }
    /* From the base: x = -D^-1 (u + U^T a), a += S_e x. */
    for (k = 0, at = 0; k < LINK_COUNT; k++) {
        size_t nc = LINK_DOF[k];
        sa_eliminated e;
        double x[LINK_MAX_DOF];
        memcpy(&e, kept + k * SA_ELIMINATED_DOUBLES, sizeof e);
        for (f = 0; f < nc; f++) x[f] = -(e.u[f] + sa_dot6(e.u_cols[f], a));
        sa_solve_small(e.d, nc, x);
        for (f = 0; f < nc; f++) {
            qdd[at + f] = x[f];
            for (i = 0; i < 6; i++) a[i] += e.s_e[f][i] * x[f];
        }
        at += nc;
    }
    return 1;
}
#endif

static void k_outputs(double t, const double *q, const double *qd, const double *qdd, const double *dir,
                      const double *p, const double *aux, double *out, double *scratch)
{
    (void)qdd; (void)dir; (void)aux;
    links_outputs(t, q, qd, p, out, scratch);
}

#if LINK_SHAPE
/* The shape: the base, then the end of each element: row r ends after
 * links LINK_ROW_FROM[r - 1] to LINK_ROW_FROM[r] - 1 (a kink's turn goes
 * with the element after it), each a point and the section's quaternion. */
static void links_shape(double t, const double *q, const double *p, double *out, double *w)
{
    double *loads = w, *o = loads + 3 * LINK_LOADS + 1, *zero = o + LINK_POSE_LEN, *scratch = zero + NQ_LINKS;
    double r[3][3], quat[4], pos[3], cp[LINK_CELL_PARAMS], x[LINK_MAX_DOF], xd[LINK_MAX_DOF];
    size_t k, row = 0;
    int i;
    memset(zero, 0, NQ_LINKS * sizeof(double));
    for (i = 0; i < 3; i++) pos[i] = p[BASE_POSITION[i]];
    sa_base(p, r, quat);
    links_loads(t, q, zero, p, loads, scratch);
    for (;;) {
        double d[3], q2[4];
        for (i = 0; i < 3; i++) out[7 * row + i] = pos[i];
        for (i = 0; i < 4; i++) out[7 * row + 3 + i] = quat[i];
        row++;
        if (row == LINK_ROWS) break;
        for (k = LINK_ROW_FROM[row - 1]; k < LINK_ROW_FROM[row]; k++) {
            sa_link_params(k, p, loads, cp);
            sa_local(k, p, q, x);
            sa_local(k, p, zero, xd);
            cell_pose(LINK_CELL[k], x, xd, cp, o, scratch);
            sa_turn(r, o + POSE_END, d);
            for (i = 0; i < 3; i++) pos[i] += d[i];
            sa_compose(r, o + POSE_ROTATION);
            sa_quat_mul(quat, o + POSE_QUAT, q2);
            memcpy(quat, q2, sizeof q2);
        }
    }
}

static void k_shape(double t, const double *q, const double *qd, const double *qdd, const double *dir,
                    const double *p, const double *aux, double *out, double *scratch)
{
    (void)qd; (void)qdd; (void)dir; (void)aux;
    links_shape(t, q, p, out, scratch);
}
#endif
