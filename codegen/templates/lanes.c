/* The lane-wise arithmetic of the model (codegen/templates/lanes.c, copied verbatim by the
 * generator first into stewart_internal.h, which the model's units share): the vector of STEWART_LANES doubles of the
 * model and its sqrt, sin, cos and tanh.  Every operation is IEEE arithmetic on each lane
 * alone (the model is compiled without contraction into fused multiply-adds:
 * -ffp-contract=off), so a state gives the same bits in any lane of any block, on every
 * instruction set.  Compiles on its own against stewart_model.h. */
#include "stewart_model.h"

#include <float.h>
#include <math.h>
#include <stddef.h>

#if defined(__aarch64__)
#include <arm_neon.h>
#endif

/* STEWART_LANES doubles, and the masks (and per-lane statuses) comparisons of them give. */
typedef double stewart_vd __attribute__((vector_size(8 * STEWART_LANES)));
typedef __typeof__((stewart_vd){0} < (stewart_vd){0}) stewart_vl;

static stewart_vd vsplat(double a)
{
    stewart_vd v;
    int lane;
    for (lane = 0; lane < STEWART_LANES; ++lane) {
        v[lane] = a;
    }
    return v;
}

/* sqrt, lane-wise (correctly rounded, as sqrt).  On x86-64 the one instruction is written as
 * assembly rather than as an intrinsic of <immintrin.h>, whose parsing took 0.12 s of CPU of
 * every unit's compile, a fifth of the model's (same instruction, same speed). */
static stewart_vd vsqrt(stewart_vd a)
{
#if STEWART_LANES == 8 && defined(__AVX512F__)
    __asm__("vsqrtpd %1, %0" : "=v"(a) : "v"(a));
    return a;
#elif (STEWART_LANES == 4 || STEWART_LANES == 2) && defined(__AVX__)
    __asm__("vsqrtpd %1, %0" : "=x"(a) : "x"(a));
    return a;
#elif STEWART_LANES == 2 && defined(__SSE2__)
    __asm__("sqrtpd %1, %0" : "=x"(a) : "x"(a));
    return a;
#elif STEWART_LANES == 2 && defined(__aarch64__)
    return (stewart_vd)vsqrtq_f64((float64x2_t)a);
#else
    int lane;
    for (lane = 0; lane < STEWART_LANES; ++lane) {
        a[lane] = sqrt(a[lane]);
    }
    return a;
#endif
}

/* All lanes STEWART_OK (a mask of no lanes). */
static stewart_vl vnone(void)
{
    const stewart_vd zero = vsplat(0.0);
    return zero != zero;
}

/* |a|, lane-wise (the sign bit cleared). */
static stewart_vd vabs(stewart_vd a)
{
    return (stewart_vd)((stewart_vl)a & ~(stewart_vl)vsplat(-0.0));
}

/* -a where mask, else a, lane-wise. */
static stewart_vd vnegate(stewart_vl mask, stewart_vd a)
{
    return (stewart_vd)((stewart_vl)a ^ (mask & (stewart_vl)vsplat(-0.0)));
}

/* a where mask, else b, lane-wise. */
static stewart_vd vselect(stewart_vl mask, stewart_vd a, stewart_vd b)
{
    return (stewart_vd)(((stewart_vl)a & mask) | ((stewart_vl)b & ~mask));
}

/* sin (cosine == 0) or cos of a, lane-wise, to within an ulp of libm's: a = n pi/2 + r
 * (Cody-Waite, pi/2 in three parts of 33 bits, so n pi/2 is exact for |n| < 2^20), then the
 * fdlibm kernels of sin and cos on |r| <= pi/4 by the quadrant n mod 4.  Lanes with
 * |a| >= 2^19 (or not finite) take libm's. */
static stewart_vd vsincos(stewart_vd a, int cosine)
{
    const double shift = 6755399441055744.0; /* 1.5 * 2^52: t's last bits hold n */
    const stewart_vd t = a * 6.36619772367581382433e-01 + shift, n = t - shift;
    const stewart_vd r = ((a - n * 1.57079632673412561417e+00) - n * 6.07710050630396597660e-11)
        - n * 2.02226624871116645580e-21;
    const stewart_vl quadrant = ((stewart_vl)t & 3) + cosine;
    const stewart_vd z = r * r, hz = 0.5 * z, w = 1.0 - hz;
    const stewart_vd sin_r = r + z * r * (-1.66666666666666324348e-01 + z * (8.33333333332248946124e-03
        + z * (-1.98412698298579493134e-04 + z * (2.75573137070700676789e-06 + z * (-2.50507602534068634195e-08
        + z * 1.58969099521155010221e-10)))));
    const stewart_vd cos_r = w + (((1.0 - w) - hz) + z * z * (4.16666666666666019037e-02
        + z * (-1.38888888888741095749e-03 + z * (2.48015872894767294178e-05 + z * (-2.75573143513906633035e-07
        + z * (2.08757232129817482790e-09 + z * -1.13596475577881948265e-11))))));
    stewart_vd v = vnegate((quadrant & 2) != 0, vselect((quadrant & 1) != 0, cos_r, sin_r));
    const stewart_vl far = ~(vabs(a) < 524288.0);
    int lane;
    for (lane = 0; lane < STEWART_LANES; ++lane) {
        if (far[lane]) {
            v[lane] = cosine ? cos(a[lane]) : sin(a[lane]);
        }
    }
    return v;
}

static stewart_vd vsin(stewart_vd a)
{
    return vsincos(a, 0);
}

static stewart_vd vcos(stewart_vd a)
{
    return vsincos(a, 1);
}

/* tanh of a, lane-wise, to within a few ulps of 1 (absolute):
 * 1 - 2 / (e^t + 1) with t = 2 |a| and the sign of a.  e^t = 2^k e^r with t = k ln 2 + r
 * (Cody-Waite, ln 2 in two parts, |r| <= ln 2 / 2) and e^r by its Taylor series to r^13
 * in Horner form, coefficients 1/n! (remainder < 2e-16); |a| > 20 counts as 20 (1 - tanh(20) < 2^-55).  NaN stays NaN. */
static stewart_vd vtanh(stewart_vd a)
{
    const double shift = 6755399441055744.0; /* 1.5 * 2^52: kf's last bits hold k */
    const stewart_vd m = vabs(a), t = 2.0 * vselect(m > 20.0, vsplat(20.0), m);
    const stewart_vd kf = t * 1.44269504088896338700e+00 + shift, k = kf - shift;
    const stewart_vd r = (t - k * 6.93147180369123816490e-01) - k * 1.90821492927058770002e-10;
    stewart_vd e = 1.6059043836821613e-10 * r + 2.08767569878681e-09;
    e = e * r + 2.505210838544172e-08;
    e = e * r + 2.755731922398589e-07;
    e = e * r + 2.7557319223985893e-06;
    e = e * r + 2.48015873015873e-05;
    e = e * r + 0.0001984126984126984;
    e = e * r + 0.001388888888888889;
    e = e * r + 0.008333333333333333;
    e = e * r + 0.041666666666666664;
    e = e * r + 0.16666666666666666;
    e = e * r + 0.5;
    e = e * r + 1.0;
    e = e * r + 1.0;
    e *= (stewart_vd)((((stewart_vl)kf - (stewart_vl)vsplat(shift)) + 1023) << 52);
    return vnegate(a < 0.0, 1.0 - 2.0 / (e + 1.0));
}
