/* sf_geo.c — see sf_geo.h for the projection and the frame convention. */
#include "sf_geo.h"

#include <math.h>
#include <stddef.h>

#include "sf_error.h"

#define WGS84_A_M 6378137.0
#define WGS84_E2 6.69437999014e-3
#define PI 3.14159265358979323846

static double rad(const double deg)
{
    return deg * (PI / 180.0);
}

/* The radii of the tangent plane at the origin: metres per radian of longitude and of latitude. */
static void radii(const sf_geo_ref_t *const g, double *const m_per_rad_lon, double *const m_per_rad_lat)
{
    const double phi0 = rad(g->origin_lat_deg);
    const double w = 1.0 - WGS84_E2 * sin(phi0) * sin(phi0);
    *m_per_rad_lon = WGS84_A_M / sqrt(w) * cos(phi0);
    *m_per_rad_lat = WGS84_A_M * (1.0 - WGS84_E2) / (w * sqrt(w));
}

int sf_geo_to_map(const sf_geo_ref_t *const g, const double lat_deg, const double lon_deg, double *const x_m,
                  double *const y_m)
{
    if (g == NULL || !g->valid) {
        return SF_EINVAL;
    }
    if (!(isfinite(lat_deg) && isfinite(lon_deg) && fabs(lat_deg) <= 90.0 && fabs(lon_deg) <= 180.0)) {
        return SF_ERANGE;
    }
    double k_lon, k_lat;
    radii(g, &k_lon, &k_lat);
    double dlon_deg = lon_deg - g->origin_lon_deg; /* across the antimeridian the short way round */
    dlon_deg = dlon_deg > 180.0 ? dlon_deg - 360.0 : (dlon_deg < -180.0 ? dlon_deg + 360.0 : dlon_deg);
    const double e = k_lon * rad(dlon_deg), n = k_lat * rad(lat_deg - g->origin_lat_deg);
    if (!(hypot(e, n) <= SF_GEO_MAX_RANGE_M)) {
        return SF_ERANGE;
    }
    const double th = rad(g->rotation_deg), c = cos(th), s = sin(th);
    *x_m = c * e + s * n;
    *y_m = -s * e + c * n;
    return SF_OK;
}

int sf_geo_from_map(const sf_geo_ref_t *const g, const double x_m, const double y_m, double *const lat_deg,
                    double *const lon_deg)
{
    if (g == NULL || !g->valid) {
        return SF_EINVAL;
    }
    double k_lon, k_lat;
    radii(g, &k_lon, &k_lat);
    const double th = rad(g->rotation_deg), c = cos(th), s = sin(th);
    const double e = c * x_m - s * y_m, n = s * x_m + c * y_m;
    *lat_deg = g->origin_lat_deg + n / k_lat * (180.0 / PI);
    *lon_deg = g->origin_lon_deg + e / k_lon * (180.0 / PI);
    return SF_OK;
}
