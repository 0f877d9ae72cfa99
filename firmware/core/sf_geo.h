/* sf_geo.h — WGS-84 latitude/longitude → the site's map frame, for GNSS fixes (and anything else
 * geo-located), with the site's geo-reference (sf_geo_ref_t in sf_radiomap.h).
 *
 * The projection is a local tangent plane with the WGS-84 radii of curvature at the origin's latitude
 * φ0 — the same as the analyzer's datasets/gsd_convert.project, so an imported walk's truth and the
 * firmware's GNSS fixes share one frame:
 *     e = N(φ0)·cos φ0·(λ − λ0),  n = M(φ0)·(φ − φ0)      (angles in radians)
 *     N = a / √(1 − e²·sin²φ0),  M = a·(1 − e²) / (1 − e²·sin²φ0)^1.5
 * Over a building or a campus (< 1 km) it differs from a full ENU conversion by millimetres. Then the
 * map frame is the east-north frame turned counter-clockwise by θ = rotation_deg (its axes are; a
 * vector's map coordinates turn the other way):
 *     x = cos θ·e + sin θ·n,   y = −sin θ·e + cos θ·n
 * (the same convention as site_t.map_rotation_deg for headings: heading_map = heading_en − θ).
 *
 * Errors: SF_EINVAL for a geo-reference that is not valid; SF_ERANGE for a non-finite or out-of-range
 * latitude/longitude (|lat| > 90, |lon| > 180) or a point farther than SF_GEO_MAX_RANGE_M from the
 * origin (another continent's fix, a corrupt sample: the plane is not meant for it); outputs untouched.
 * Cost: a few trigonometric calls. No state. */
#ifndef SF_GEO_H
#define SF_GEO_H

#include "sf_radiomap.h"

/* Beyond this distance from the origin a fix is refused [m]: the tangent plane's error grows with the
 * square of the distance (≈ 0.1 m at 50 km), and no walk of one site spans that. */
#define SF_GEO_MAX_RANGE_M 50000.0

int sf_geo_to_map(const sf_geo_ref_t *geo, double lat_deg, double lon_deg, double *x_m, double *y_m);

/* The inverse (for tests and the simulator's checks): map frame → latitude/longitude [deg]. SF_OK or
 * SF_EINVAL (geo not valid). */
int sf_geo_from_map(const sf_geo_ref_t *geo, double x_m, double y_m, double *lat_deg, double *lon_deg);

#endif
