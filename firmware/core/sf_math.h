/* sf_math.h — the small scalar helpers every core module uses, in one place (header-only, static
 * inline: no state, no cost beyond the call site's). */
#ifndef SF_MATH_H
#define SF_MATH_H

#include <math.h>

/* v limited to [lo, hi] (lo ≤ hi; NaN passes through). */
static inline double sf_clamp(const double v, const double lo, const double hi)
{
    return v < lo ? lo : (v > hi ? hi : v);
}

/* An angle [rad] wrapped to (−π, π]. */
static inline double sf_wrap_pi(const double a)
{
    return atan2(sin(a), cos(a));
}

#endif
