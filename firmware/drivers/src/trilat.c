// SPDX-License-Identifier: MIT
// dynaqpc drivers: trilateration (see trilat.h).
//
// Linearisation: with d_i^2 = r_i^2 - (z_i - h)^2 the horizontal range to beacon i,
//   (x - x_i)^2 + (y - y_i)^2 = d_i^2   for every i.
// Subtracting the mean of these equations removes x^2 + y^2 and leaves, for every i,
//   2 (x_i - mx) x + 2 (y_i - my) y = (x_i^2 + y_i^2 - d_i^2) - mean(x_j^2 + y_j^2 - d_j^2),
// linear in x, y. Its normal matrix is 4 n C, with C the covariance of the beacons' x, y: the
// same matrix says whether the geometry can fix both coordinates (its smaller eigenvalue is the
// squared spread along the narrowest direction) and is the one inverted. Centring the beacon
// coordinates before squaring keeps float precision: values stay in the arena's size, not its
// square times the distance from the origin.
// The linear solution weights ranges unequally (by distance) and squares noise; a few
// Gauss-Newton steps on the slant ranges fix both. The listener height is known, so the problem
// stays 2-D and the Jacobian row of beacon i is ((x - x_i) / rho_i, (y - y_i) / rho_i).
#include "drivers/trilat.h"

#include <math.h>
#include <stdbool.h>

#include "fw/fw_base.h"

static int is_finite(float v)
{
    return v == v && v < 3.0e38f && v > -3.0e38f;
}

static float residual_rms(const trilat_anchor_t *a, size_t n, float h, float x, float y)
{
    float sum = 0.0f;
    for (size_t i = 0; i < n; i++) {
        float dx = x - a[i].x, dy = y - a[i].y, dz = h - a[i].z;
        float e = sqrtf(dx * dx + dy * dy + dz * dz) - a[i].range;
        sum += e * e;
    }
    return sqrtf(sum / (float)n);
}

// The beacons' mean and the covariance of their x, y; whether that geometry can fix x and y
// (trilat_geometry_ok).
struct spread {
    float mx, my, sxx, syy, sxy, det, lambda_min;
};

static bool spread_of(const trilat_anchor_t *a, size_t n, float min_spread, struct spread *s)
{
    float mx = 0.0f, my = 0.0f;
    for (size_t i = 0; i < n; i++) {
        mx += a[i].x;
        my += a[i].y;
    }
    mx /= (float)n;
    my /= (float)n;

    // Covariance of the centred beacon positions, and the geometry check.
    float sxx = 0.0f, syy = 0.0f, sxy = 0.0f;
    for (size_t i = 0; i < n; i++) {
        float u = a[i].x - mx, v = a[i].y - my;
        sxx += u * u;
        syy += v * v;
        sxy += u * v;
    }
    sxx /= (float)n;
    syy /= (float)n;
    sxy /= (float)n;
    float tr = sxx + syy;
    float det = sxx * syy - sxy * sxy;
    float disc = sqrtf(fmaxf(tr * tr * 0.25f - det, 0.0f));
    float lambda_min = tr * 0.5f - disc;
    *s = (struct spread){mx, my, sxx, syy, sxy, det, lambda_min};
    return lambda_min >= min_spread * min_spread && det > 0.0f;
}

bool trilat_geometry_ok(const trilat_anchor_t *a, size_t n, float min_spread, float *spread_out)
{
    struct spread s = {0};
    const bool ok = n >= 3u && spread_of(a, n, min_spread, &s);
    if (spread_out != NULL) {
        *spread_out = n >= 3u ? sqrtf(fmaxf(s.lambda_min, 0.0f)) : 0.0f;
    }
    return ok;
}

int trilat_solve(const trilat_anchor_t *a, size_t n, const struct trilat_params *p,
                 trilat_result_t *out)
{
    if (n < 3u) {
        return FW_ERR_INVAL;
    }
    for (size_t i = 0; i < n; i++) {
        if (!is_finite(a[i].x) || !is_finite(a[i].y) || !is_finite(a[i].z) ||
            !is_finite(a[i].range) || a[i].range < 0.0f) {
            return FW_ERR_INVAL;
        }
    }
    struct spread s;
    if (!spread_of(a, n, p->min_spread, &s)) {
        return FW_ERR_INVAL;
    }
    const float mx = s.mx, my = s.my, sxx = s.sxx, syy = s.syy, sxy = s.sxy, det = s.det;

    // Linear least squares in centred coordinates (u, v) = (x - mx, y - my):
    //   2 u_i u + 2 v_i v = (u_i^2 + v_i^2 - d_i^2) - mean(...)
    float k_mean = 0.0f;
    for (size_t i = 0; i < n; i++) {
        float u = a[i].x - mx, v = a[i].y - my, dz = a[i].z - p->listener_z;
        float d2 = fmaxf(a[i].range * a[i].range - dz * dz, 0.0f);
        k_mean += u * u + v * v - d2;
    }
    k_mean /= (float)n;
    float bu = 0.0f, bv = 0.0f;  // A^T b / (2 n)
    for (size_t i = 0; i < n; i++) {
        float u = a[i].x - mx, v = a[i].y - my, dz = a[i].z - p->listener_z;
        float d2 = fmaxf(a[i].range * a[i].range - dz * dz, 0.0f);
        float k = u * u + v * v - d2 - k_mean;
        bu += u * k;
        bv += v * k;
    }
    bu /= 2.0f * (float)n;
    bv /= 2.0f * (float)n;
    // A^T A = 4 n C and A^T k = 2 sum(u_i k_i, v_i k_i), so [u v] = C^-1 [bu bv].
    float x = mx + (syy * bu - sxy * bv) / det;
    float y = my + (sxx * bv - sxy * bu) / det;

    // Gauss-Newton on the slant ranges.
    for (unsigned it = 0; it < p->iterations; it++) {
        float jxx = 0.0f, jyy = 0.0f, jxy = 0.0f, gx = 0.0f, gy = 0.0f;
        for (size_t i = 0; i < n; i++) {
            float dx = x - a[i].x, dy = y - a[i].y, dz = p->listener_z - a[i].z;
            float rho = sqrtf(dx * dx + dy * dy + dz * dz);
            if (rho < 1e-6f) {
                continue;  // at the beacon itself: no direction, contributes nothing
            }
            float jx = dx / rho, jy = dy / rho, e = rho - a[i].range;
            jxx += jx * jx;
            jyy += jy * jy;
            jxy += jx * jy;
            gx += jx * e;
            gy += jy * e;
        }
        float jdet = jxx * jyy - jxy * jxy;
        if (!(jdet > 1e-9f)) {
            break;  // every beacon straight above: x, y unobservable from here; keep the linear fix
        }
        float sx = (jyy * gx - jxy * gy) / jdet;
        float sy = (jxx * gy - jxy * gx) / jdet;
        x -= sx;
        y -= sy;
        if (fabsf(sx) + fabsf(sy) < 1e-6f * (1.0f + fabsf(x) + fabsf(y))) {
            break;
        }
    }
    out->x = x;
    out->y = y;
    out->residual_rms = residual_rms(a, n, p->listener_z, x, y);
    if (!is_finite(x) || !is_finite(y)) {
        return FW_ERR_INVAL;
    }
    return out->residual_rms > p->max_residual ? FW_ERR_CORRUPT : FW_OK;
}
