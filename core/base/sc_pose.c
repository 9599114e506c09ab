/* sc_pose.c: rigid transforms, see sc_pose.h. */
#include "sc_pose.h"

#include <math.h>

sc_pose sc_pose_identity(void)
{
    return (sc_pose){.pos_mm = {0.0f, 0.0f, 0.0f}, .q = {1.0f, 0.0f, 0.0f, 0.0f}};
}

sc_xform sc_xform_identity(void)
{
    return (sc_xform){.r = {1.0f, 0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f, 1.0f},
                      .t_mm = {0.0f, 0.0f, 0.0f}};
}

float sc_quat_norm2(const float q[4])
{
    return q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
}

sc_xform sc_xform_from_pose(const sc_pose *p)
{
    const float w = p->q[0], x = p->q[1], y = p->q[2], z = p->q[3];
    sc_xform r;
    r.r[0] = 1.0f - 2.0f * (y * y + z * z);
    r.r[1] = 2.0f * (x * y - w * z);
    r.r[2] = 2.0f * (x * z + w * y);
    r.r[3] = 2.0f * (x * y + w * z);
    r.r[4] = 1.0f - 2.0f * (x * x + z * z);
    r.r[5] = 2.0f * (y * z - w * x);
    r.r[6] = 2.0f * (x * z - w * y);
    r.r[7] = 2.0f * (y * z + w * x);
    r.r[8] = 1.0f - 2.0f * (x * x + y * y);
    r.t_mm[0] = p->pos_mm[0];
    r.t_mm[1] = p->pos_mm[1];
    r.t_mm[2] = p->pos_mm[2];
    return r;
}

sc_xform sc_xform_compose(const sc_xform *b, const sc_xform *a)
{
    sc_xform o;
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            o.r[i * 3 + j] = b->r[i * 3 + 0] * a->r[0 * 3 + j] + b->r[i * 3 + 1] * a->r[1 * 3 + j] +
                             b->r[i * 3 + 2] * a->r[2 * 3 + j];
        }
        o.t_mm[i] = b->r[i * 3 + 0] * a->t_mm[0] + b->r[i * 3 + 1] * a->t_mm[1] +
                    b->r[i * 3 + 2] * a->t_mm[2] + b->t_mm[i];
    }
    return o;
}

sc_xform sc_xform_inverse(const sc_xform *a)
{
    sc_xform o;
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            o.r[i * 3 + j] = a->r[j * 3 + i];
        }
    }
    for (int i = 0; i < 3; i++) {
        o.t_mm[i] = -(o.r[i * 3 + 0] * a->t_mm[0] + o.r[i * 3 + 1] * a->t_mm[1] +
                      o.r[i * 3 + 2] * a->t_mm[2]);
    }
    return o;
}

void sc_xform_rotate(const sc_xform *x, const float v[3], float out[3])
{
    const float a = v[0], b = v[1], c = v[2];
    out[0] = x->r[0] * a + x->r[1] * b + x->r[2] * c;
    out[1] = x->r[3] * a + x->r[4] * b + x->r[5] * c;
    out[2] = x->r[6] * a + x->r[7] * b + x->r[8] * c;
}

void sc_xform_apply(const sc_xform *x, const float p[3], float out[3])
{
    sc_xform_rotate(x, p, out);
    out[0] += x->t_mm[0];
    out[1] += x->t_mm[1];
    out[2] += x->t_mm[2];
}

int sc_xform_is_rigid(const sc_xform *x, float tol)
{
    for (int i = 0; i < 9; i++) {
        if (!isfinite(x->r[i])) {
            return 0;
        }
    }
    for (int i = 0; i < 3; i++) {
        if (!isfinite(x->t_mm[i])) {
            return 0;
        }
    }
    for (int i = 0; i < 3; i++) {
        for (int j = 0; j < 3; j++) {
            float d = x->r[i * 3 + 0] * x->r[j * 3 + 0] + x->r[i * 3 + 1] * x->r[j * 3 + 1] +
                      x->r[i * 3 + 2] * x->r[j * 3 + 2];
            float want = i == j ? 1.0f : 0.0f;
            if (fabsf(d - want) > tol) {
                return 0;
            }
        }
    }
    float det = x->r[0] * (x->r[4] * x->r[8] - x->r[5] * x->r[7]) -
                x->r[1] * (x->r[3] * x->r[8] - x->r[5] * x->r[6]) +
                x->r[2] * (x->r[3] * x->r[7] - x->r[4] * x->r[6]);
    return fabsf(det - 1.0f) <= tol;
}

sc_pose sc_pose_from_xform(const sc_xform *x)
{
    /* Shepperd's method: pick the largest of w, x, y, z to divide by (stable everywhere) */
    const float *m = x->r;
    const float tr = m[0] + m[4] + m[8];
    float q[4];
    if (tr > 0.0f) {
        const float s = sqrtf(tr + 1.0f) * 2.0f;
        q[0] = 0.25f * s;
        q[1] = (m[7] - m[5]) / s;
        q[2] = (m[2] - m[6]) / s;
        q[3] = (m[3] - m[1]) / s;
    } else if (m[0] > m[4] && m[0] > m[8]) {
        const float s = sqrtf(1.0f + m[0] - m[4] - m[8]) * 2.0f;
        q[0] = (m[7] - m[5]) / s;
        q[1] = 0.25f * s;
        q[2] = (m[1] + m[3]) / s;
        q[3] = (m[2] + m[6]) / s;
    } else if (m[4] > m[8]) {
        const float s = sqrtf(1.0f + m[4] - m[0] - m[8]) * 2.0f;
        q[0] = (m[2] - m[6]) / s;
        q[1] = (m[1] + m[3]) / s;
        q[2] = 0.25f * s;
        q[3] = (m[5] + m[7]) / s;
    } else {
        const float s = sqrtf(1.0f + m[8] - m[0] - m[4]) * 2.0f;
        q[0] = (m[3] - m[1]) / s;
        q[1] = (m[2] + m[6]) / s;
        q[2] = (m[5] + m[7]) / s;
        q[3] = 0.25f * s;
    }
    const float n = sqrtf(sc_quat_norm2(q));
    const float sign = q[0] < 0.0f ? -1.0f : 1.0f;
    sc_pose p;
    for (int i = 0; i < 4; i++) {
        p.q[i] = sign * q[i] / n;
    }
    for (int i = 0; i < 3; i++) {
        p.pos_mm[i] = x->t_mm[i];
    }
    return p;
}
