/*
 * scara_pin._speedups: the per-call hot paths in C, for the speed targets of the per-call API.
 *
 * Nothing here is needed for correctness: every function has a pure-Python equivalent that scara_pin uses
 * when this module is not built (see scara_pin/_fast.py), and the tests run both routes against each other.
 *
 *   q_ok(q)        True when q is obviously valid for the kinematics: a 1-D float64 ndarray (native byte
 *                  order, aligned) of exactly 4
 *                  values whose sum of squares is at most the bound given to set_q_max2() (NaN and inf fail
 *                  this comparison). False sends q to the full Python check; it never lets a bad q through.
 *   task_rows(J)   a new (4, n) float64 array: rows 0, 1, 2 and 5 (x, y, z, wz) of a (6, n) float64 Jacobian.
 *   nearest(params, target, reference, weights, branch)
 *                  the closed-form SCARA IK solution nearest to `reference`, for the regular case only:
 *                  the same expressions as scara_pin.ik.solve(), every 2 pi turn of the shoulder, elbow and
 *                  wrist inside the limits, both branches (branch "all", "left" or "right"), and the
 *                  minimum of sum_i w_i (q_i - ref_i)^2 with the first one kept on a tie (solve()'s order:
 *                  right before left, then by shoulder, elbow and wrist turn). It returns None whenever it
 *                  has no solution to give (out of reach, limits, stroke, a free shoulder, inputs that are
 *                  not 4 finite floats, ...): the caller then takes the Python route, which gives the reason.
 */
#define PY_SSIZE_T_CLEAN
#include <Python.h>
#include <math.h>
#define NPY_NO_DEPRECATED_API NPY_2_0_API_VERSION
#include <numpy/arrayobject.h>

#define API_VERSION 2 /* bump with any change of a function's arguments, results or the Geometry layout */

static PyObject *str_all = NULL; /* interned "all" */
static double q_max2 = -1.0; /* set by set_q_max2(); negative: q_ok() says False to everything */

/* The geometry, as packed by scara_pin.ik.ScaraGeometry (_C_FIELDS there): doubles in this order. */
typedef struct {
    double ra, rb, rc, ip;     /* q indices of shoulder, elbow, wrist and the vertical joint */
    double s_a, s_b, s_c, s_p; /* axis signs */
    double lo_a, hi_a, lo_b, hi_b, lo_c, hi_c, lo_p, hi_p; /* limits */
    double lt_a, ht_a, lt_b, ht_b, lt_c, ht_c, lt_p, ht_p; /* limits widened by LIMIT_TOL */
    double z0, yaw0, a1x, a1y, tx, ty;
    double l1, l2, beta1, beta2, reach, l12, d12;
    double inner_min;    /* r_min - REACH_TOL; NaN when unknown (the Python route decides) */
    double tool_on_axis; /* 1.0 when the tool point is on the wrist axis */
    double snap_tol, free_r, singular_tol, two_pi;
} Geometry;

/* A float64 array in the machine's byte order, aligned: its doubles can be read in place. */
static inline int native_f64(PyArrayObject *a) {
    return PyArray_TYPE(a) == NPY_DOUBLE && PyArray_ISNOTSWAPPED(a) && PyArray_ISALIGNED(a);
}

/* 4 finite doubles from a 1-D float64 ndarray of 4 values, or a tuple/list of 4 Python floats. */
static int read4(PyObject *obj, double out[4]) {
    if (PyArray_Check(obj)) {
        PyArrayObject *a = (PyArrayObject *)obj;
        if (!native_f64(a) || PyArray_NDIM(a) != 1 || PyArray_DIM(a, 0) != 4) return 0;
        const char *p = PyArray_BYTES(a);
        npy_intp st = PyArray_STRIDE(a, 0);
        for (int i = 0; i < 4; i++) out[i] = *(const double *)(p + i * st);
    } else if (PyTuple_CheckExact(obj) || PyList_CheckExact(obj)) {
        if (PySequence_Fast_GET_SIZE(obj) != 4) return 0;
        PyObject **items = PySequence_Fast_ITEMS(obj);
        for (int i = 0; i < 4; i++) {
            if (!PyFloat_CheckExact(items[i])) return 0;
            out[i] = PyFloat_AS_DOUBLE(items[i]);
        }
    } else {
        return 0;
    }
    for (int i = 0; i < 4; i++)
        if (!isfinite(out[i])) return 0;
    return 1;
}

static PyObject *set_q_max2(PyObject *self, PyObject *arg) {
    double v = PyFloat_AsDouble(arg);
    if (v == -1.0 && PyErr_Occurred()) return NULL;
    q_max2 = v;
    Py_RETURN_NONE;
}

static PyObject *q_ok(PyObject *self, PyObject *q) {
    if (!PyArray_CheckExact(q)) Py_RETURN_FALSE;
    PyArrayObject *a = (PyArrayObject *)q;
    if (!native_f64(a) || PyArray_NDIM(a) != 1 || PyArray_DIM(a, 0) != 4) Py_RETURN_FALSE;
    const char *p = PyArray_BYTES(a);
    npy_intp st = PyArray_STRIDE(a, 0);
    double s = 0.0;
    for (int i = 0; i < 4; i++) {
        double v = *(const double *)(p + i * st);
        s += v * v;
    }
    if (s <= q_max2) Py_RETURN_TRUE; /* NaN fails */
    Py_RETURN_FALSE;
}

static PyObject *task_rows(PyObject *self, PyObject *obj) {
    static const int rows[4] = {0, 1, 2, 5};
    if (!PyArray_Check(obj)) {
        PyErr_SetString(PyExc_TypeError, "task_rows: expected a (6, n) float64 array");
        return NULL;
    }
    PyArrayObject *J = (PyArrayObject *)obj;
    if (!native_f64(J) || PyArray_NDIM(J) != 2 || PyArray_DIM(J, 0) != 6) {
        PyErr_SetString(PyExc_TypeError, "task_rows: expected a (6, n) float64 array");
        return NULL;
    }
    npy_intp n = PyArray_DIM(J, 1);
    npy_intp dims[2] = {4, n};
    PyArrayObject *out = (PyArrayObject *)PyArray_SimpleNew(2, dims, NPY_DOUBLE);
    if (out == NULL) return NULL;
    double *o = (double *)PyArray_DATA(out);
    const char *p = PyArray_BYTES(J);
    npy_intp s0 = PyArray_STRIDE(J, 0), s1 = PyArray_STRIDE(J, 1);
    for (int i = 0; i < 4; i++)
        for (npy_intp j = 0; j < n; j++) o[i * n + j] = *(const double *)(p + rows[i] * s0 + j * s1);
    return (PyObject *)out;
}

/* the first value + 2 pi k at or above the widened lower limit (solve(): v + ceil((lt - v) / 2 pi) 2 pi) */
static inline double first_turn(double v, double lt, double two_pi) { return v + ceil((lt - v) / two_pi) * two_pi; }

static inline double clamp(double v, double lo, double hi) {
    double m = lo > v ? lo : v;
    return hi < m ? hi : m;
}

#define MAX_TURNS 64 /* more 2 pi turns than this inside one joint's range: leave it to Python */

static PyObject *nearest(PyObject *self, PyObject *const *args, Py_ssize_t nargs) {
    if (nargs != 5) {
        PyErr_SetString(PyExc_TypeError, "nearest(params, target, reference, weights, branch)");
        return NULL;
    }
    if (!PyBytes_CheckExact(args[0]) || PyBytes_GET_SIZE(args[0]) != (Py_ssize_t)sizeof(Geometry)) {
        PyErr_SetString(PyExc_TypeError, "nearest: params must be the geometry's packed bytes");
        return NULL;
    }
    const Geometry *g = (const Geometry *)PyBytes_AS_STRING(args[0]);
    const int ia = (int)g->ra, ib = (int)g->rb, ic = (int)g->rc, ip = (int)g->ip;
    if (ia < 0 || ia > 3 || ib < 0 || ib > 3 || ic < 0 || ic > 3 || ip < 0 || ip > 3 || (ia + ib + ic + ip) != 6 ||
        ia == ib || ia == ic || ia == ip || ib == ic || ib == ip || ic == ip) {
        PyErr_SetString(PyExc_ValueError, "nearest: the packed joint indices are not a permutation of 0..3");
        return NULL;
    }
    double t[4], ref[4], w[4] = {1.0, 1.0, 1.0, 1.0};
    if (!read4(args[1], t) || !read4(args[2], ref)) Py_RETURN_NONE;
    if (args[3] != Py_None) {
        if (!read4(args[3], w)) Py_RETURN_NONE;
        for (int i = 0; i < 4; i++)
            if (!(w[i] >= 0.0)) Py_RETURN_NONE;
    }
    int branch; /* 0 all, 1 left, 2 right */
    if (args[4] == str_all) branch = 0; /* the default argument: the interned literal */
    else if (!PyUnicode_Check(args[4])) Py_RETURN_NONE;
    else if (PyUnicode_CompareWithASCIIString(args[4], "all") == 0) branch = 0;
    else if (PyUnicode_CompareWithASCIIString(args[4], "left") == 0) branch = 1;
    else if (PyUnicode_CompareWithASCIIString(args[4], "right") == 0) branch = 2;
    else Py_RETURN_NONE;

    const double two_pi = g->two_pi, pi = 0.5 * g->two_pi;
    const double x = t[0], y = t[1], z = t[2], yaw = t[3];
    const double alpha = yaw - g->yaw0;
    /* vertical joint */
    double qp = (z - g->z0) / g->s_p;
    if (!(g->lt_p <= qp && qp <= g->ht_p)) Py_RETURN_NONE;
    qp = clamp(qp, g->lo_p, g->hi_p);
    /* wrist point and reach */
    double wx, wy;
    if (g->tool_on_axis != 0.0 && x != 0.0 && y != 0.0) {
        wx = x - g->a1x;
        wy = y - g->a1y;
    } else {
        double ca = cos(alpha), sa = sin(alpha);
        wx = x - (ca * g->tx - sa * g->ty) - g->a1x;
        wy = y - (sa * g->tx + ca * g->ty) - g->a1y;
    }
    double r = sqrt(wx * wx + wy * wy); /* as solve(): both the C library's sqrt, bit for bit */
    if (r > g->reach || !(r >= g->inner_min) || !(r > g->free_r)) Py_RETURN_NONE;
    /* elbow angle gamma in [0, pi], by the half-angle form */
    const double l12 = g->l12, d12 = g->d12, snap = g->snap_tol * l12;
    double outer = l12 - r;
    if (snap > outer) outer = 0.0;
    outer *= l12 + r;
    double inner = r - d12;
    if (snap > inner) inner = 0.0;
    inner *= r + d12;
    const double gamma = 2.0 * atan2(sqrt(outer), sqrt(inner));
    const int singular = gamma < g->singular_tol || pi - gamma < g->singular_tol;
    const double heading = atan2(wy, wx);
    const double lean = atan2(g->l2 * sin(gamma), g->l1 + g->l2 * cos(gamma));
    /* elbows: (gamma, theta1, label) with label 2 = right, 1 = left */
    double eg[2], et[2];
    int el[2], ne;
    if (singular) {
        eg[0] = gamma, et[0] = heading - lean, el[0] = gamma < 1.0 ? 2 : 1, ne = 1;
    } else {
        eg[0] = gamma, et[0] = heading - lean, el[0] = 2;
        eg[1] = -gamma, et[1] = heading + lean, el[1] = 1, ne = 2;
    }
    double best[4], best_cost = INFINITY;
    int found = 0;
    for (int e = 0; e < ne; e++) {
        if (!(branch == 0 || el[e] == branch || singular)) continue;
        const double phi1 = et[e] - g->beta1;
        const double phi2 = eg[e] + g->beta1 - g->beta2;
        double qa_list[MAX_TURNS], qb_list[MAX_TURNS];
        int na = 0, nb = 0;
        for (double v = first_turn(g->s_a * phi1, g->lt_a, two_pi); v <= g->ht_a; v += two_pi) {
            if (na == MAX_TURNS) Py_RETURN_NONE;
            qa_list[na++] = clamp(v, g->lo_a, g->hi_a);
        }
        for (double v = first_turn(g->s_b * phi2, g->lt_b, two_pi); v <= g->ht_b; v += two_pi) {
            if (nb == MAX_TURNS) Py_RETURN_NONE;
            qb_list[nb++] = clamp(v, g->lo_b, g->hi_b);
        }
        for (int i = 0; i < na; i++) {
            for (int j = 0; j < nb; j++) {
                const double qa = qa_list[i], qb = qb_list[j];
                /* the wrist takes up whatever turns the shoulder and elbow add, to keep alpha */
                const double vc = g->s_c * (alpha - g->s_a * qa - g->s_b * qb);
                int nc = 0;
                for (double v = first_turn(vc, g->lt_c, two_pi); v <= g->ht_c; v += two_pi) {
                    if (++nc > MAX_TURNS) Py_RETURN_NONE;
                    double q[4];
                    q[ia] = qa, q[ib] = qb, q[ic] = clamp(v, g->lo_c, g->hi_c), q[ip] = qp;
                    double cost = 0.0;
                    for (int k = 0; k < 4; k++) {
                        const double d = q[k] - ref[k];
                        cost += w[k] * (d * d);
                    }
                    if (!found || cost < best_cost) {
                        found = 1, best_cost = cost;
                        for (int k = 0; k < 4; k++) best[k] = q[k];
                    }
                }
            }
        }
    }
    if (!found) Py_RETURN_NONE;
    npy_intp dims[1] = {4};
    PyArrayObject *out = (PyArrayObject *)PyArray_SimpleNew(1, dims, NPY_DOUBLE);
    if (out == NULL) return NULL;
    double *o = (double *)PyArray_DATA(out);
    for (int k = 0; k < 4; k++) o[k] = best[k];
    return (PyObject *)out;
}

static PyObject *geometry_size(PyObject *self, PyObject *unused) {
    return PyLong_FromSsize_t((Py_ssize_t)(sizeof(Geometry) / sizeof(double)));
}

static PyMethodDef methods[] = {
    {"q_ok", q_ok, METH_O, "True when q is a 1-D float64 array of 4 moderate finite values."},
    {"set_q_max2", set_q_max2, METH_O, "Set the bound on the sum of squares q_ok() accepts."},
    {"task_rows", task_rows, METH_O, "Rows 0, 1, 2, 5 of a (6, n) float64 Jacobian, as a new array."},
    {"nearest", (PyCFunction)(void (*)(void))nearest, METH_FASTCALL,
     "nearest(params, target, reference, weights, branch): the nearest closed-form IK solution, or None."},
    {"geometry_size", geometry_size, METH_NOARGS, "The number of doubles in the packed geometry."},
    {NULL, NULL, 0, NULL},
};

static struct PyModuleDef module = {
    PyModuleDef_HEAD_INIT, "_speedups", "scara_pin's hot paths in C.", -1, methods, NULL, NULL, NULL, NULL,
};

PyMODINIT_FUNC PyInit__speedups(void) {
    import_array();
    str_all = PyUnicode_InternFromString("all");
    if (str_all == NULL) return NULL;
    PyObject *m = PyModule_Create(&module);
    if (m == NULL) return NULL;
    /* scara_pin._fast uses the module only when this equals its own API_VERSION (a stale build is ignored) */
    if (PyModule_AddIntConstant(m, "API_VERSION", API_VERSION) < 0) {
        Py_DECREF(m);
        return NULL;
    }
    return m;
}
