/* sf_fix_reason.c — the words of the FIX records' reasons (fix_t.reason_text), apart from the
 * fusion's math and control (sf_fusion.c). */
#include "sf_fusion.h"

_Static_assert(sf_fix_reason_count == 11, "reasons mirror fix_t.REASON_*");

const char *sf_fix_reason_text(const int reason)
{
    static const char *const text[sf_fix_reason_count] = {
        [sf_fix_reason_accepted] = "accepted",
        [sf_fix_reason_gate] = "rejected: outside the innovation gate",
        [sf_fix_reason_too_few_aps] = "rejected: too few access points",
        [sf_fix_reason_no_map] = "rejected: no radio map",
        [sf_fix_reason_floor_mismatch] = "rejected: floor differs from the scheme's floor",
        [sf_fix_reason_not_initialised] = "rejected: scheme not initialised",
        [sf_fix_reason_initialised] = "accepted: initialised the scheme",
        [sf_fix_reason_recovery] = "accepted: recovery after consecutive rejections",
        [sf_fix_reason_scheme_ignores] = "ignored: the scheme does not use fixes of this source",
        [sf_fix_reason_inaccurate] = "rejected: the source's own accuracy or position is unusable",
        [sf_fix_reason_context_off] = "ignored: the controller keeps this source off in this context",
    };
    return reason >= 0 && reason < sf_fix_reason_count ? text[reason] : "unknown reason";
}
