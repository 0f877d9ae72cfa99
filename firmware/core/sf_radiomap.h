/* sf_radiomap.h — the site as the core sees it: floors, map rotation and the radio map, as plain
 * read-only arrays owned by the caller (the board layer loads them from the site file, the only place
 * that allocates; see firmware/board/sf_site.h and lcmtypes/stridefix/site_t.lcm).
 *
 * Radio map layout: sparse and AP-major, which is the inverted index AP → reference points that makes
 * a match cost follow the APs heard, not the map size. Access point a (0 ≤ a < n_ap, BSSIDs ascending
 * so a scan's BSSID is found by binary search) owns entries ap_first[a] .. ap_first[a+1]−1; entry i
 * says that reference point entry_rp[i] heard it entry_count[i] times out of rp_scans[entry_rp[i]]
 * scans, with mean entry_mean_dbm[i] and spread entry_std_db[i]. Within one AP, entries are sorted by
 * reference point. Positions are in the map frame [m]; floors are indices (lowest_floor …). */
#ifndef SF_RADIOMAP_H
#define SF_RADIOMAP_H

#include <stdbool.h>
#include <stdint.h>

typedef struct {
    int32_t n_ap;
    const int64_t *ap_bssid; /* [n_ap], strictly ascending */
    const int32_t *ap_first; /* [n_ap + 1], ap_first[0] = 0, ap_first[n_ap] = n_entries, non-decreasing */
    int32_t n_rp;
    const float *rp_x_m;     /* [n_rp] */
    const float *rp_y_m;     /* [n_rp] */
    const int16_t *rp_floor; /* [n_rp] */
    const int32_t *rp_scans; /* [n_rp], ≥ 1 */
    int32_t n_entries;
    const int32_t *entry_rp;       /* [n_entries], 0 ≤ value < n_rp */
    const float *entry_mean_dbm;   /* [n_entries] */
    const float *entry_std_db;     /* [n_entries], ≥ 0 */
    const int32_t *entry_count;    /* [n_entries], 1 ≤ value ≤ rp_scans[entry_rp] */
} sf_radiomap_t;

/* The ekf's Wi-Fi fix-error model as the site measured it (sf_ekf.h; the ekf.fix_* parameters when
 * not valid): one fix's error covariance = floor [m², xx, xy, yy] + accuracy² · per-accuracy² part,
 * the correlated part's σ [m] and length [m], the least white share. */
typedef struct {
    bool valid;
    double floor_cov_m2[3]; /* one fix's error = floor_cov_m2 + accuracy² · cov_per_acc2 */
    double cov_per_acc2[3];
    double bias_sigma_m;
    double bias_length_m;
    double white_share;
} sf_fix_model_t;

/* Geo-reference (site file v2): the map frame's origin on WGS-84 and its rotation, so GNSS fixes and
 * geo-located beacons map into the site frame (sf_geo.h: a local tangent plane with the WGS-84 radii
 * at the origin, the same projection as the analyzer's gsd_convert.project). */
typedef struct {
    bool valid;
    double origin_lat_deg;
    double origin_lon_deg;
    double origin_alt_m;
    double rotation_deg; /* map frame = local east-north frame turned counter-clockwise by this [deg] */
} sf_geo_ref_t;

/* Floor plan (site file v2): wall segments per floor, map frame [m]. A walker never crosses one; a
 * site without walls (n_walls = 0) constrains nothing. Segments are in any order. */
typedef struct {
    int32_t n_walls;
    const float *x0_m;    /* [n_walls] */
    const float *y0_m;    /* [n_walls] */
    const float *x1_m;    /* [n_walls] */
    const float *y1_m;    /* [n_walls] */
    const int16_t *floor; /* [n_walls] */
} sf_floor_plan_t;

/* Port kinds, identical to site_t.PORT_*. */
enum { sf_port_door = 1, sf_port_stairs = 2, sf_port_elevator = 3 };

/* Ports (site file v2): where a walker may change floor (stairs, elevator) or context (door): a disc
 * of radius_m about (x_m, y_m) that joins floors floor_lo .. floor_hi (a door: floor_lo = floor_hi). */
typedef struct {
    int32_t n_ports;
    const int16_t *kind;     /* [n_ports], sf_port_* (int16, not int8: lcm-gen copies an int8 array with
                              * memcpy, undefined for the NULL pointer of a site without ports) */
    const float *x_m;        /* [n_ports] */
    const float *y_m;        /* [n_ports] */
    const float *radius_m;   /* [n_ports], > 0 */
    const int16_t *floor_lo; /* [n_ports] */
    const int16_t *floor_hi; /* [n_ports], ≥ floor_lo */
} sf_ports_t;

/* Port q joins `floor` (floor_lo ≤ floor ≤ floor_hi). */
static inline bool sf_port_joins(const sf_ports_t *const ports, const int32_t q, const int32_t floor)
{
    return floor >= ports->floor_lo[q] && floor <= ports->floor_hi[q];
}

/* BLE beacons (site file v2), ids (48-bit MAC) strictly ascending so a reading's beacon is found by
 * binary search, with the site's log-distance path-loss model RSSI(d) = rssi_1m_dbm − 10·n·log10(d)
 * (n = path_loss_exponent; a beacon's own rssi_1m_dbm when finite, else the site's). */
typedef struct {
    int32_t n_beacons;
    const int64_t *id;          /* [n_beacons], strictly ascending, 0 … 2^48 − 1 */
    const float *x_m;           /* [n_beacons] */
    const float *y_m;           /* [n_beacons] */
    const int16_t *floor;       /* [n_beacons] */
    const float *rssi_1m_dbm;   /* [n_beacons], NaN: the site's */
    double site_rssi_1m_dbm;    /* the site's RSSI at 1 m [dBm] */
    double path_loss_exponent;  /* n, > 0 */
    double range_sigma_db;      /* RSSI spread about the model [dB], > 0 */
} sf_beacons_t;

/* Context kinds, identical to site_t.CONTEXT_* and context_t.KIND_*. */
enum { sf_context_outdoor = 1, sf_context_building = 2, sf_context_floor = 3 };

/* The positioning context map (site file v3; Jäger, Süß, Becker §III-C) of the multi-scheme controller
 * (sf_controller.h): buildings with outlines, per-port extras beside sf_ports_t (building, outdoor,
 * staircase steps and endpoints), the ports' reachability links, the contexts with their localization
 * scheme descriptor (scheme, method) and context determination descriptor (method, constellation).
 * n_contexts = 0: no controller (then every other array may be NULL). Field meanings: site_t.lcm. */
typedef struct {
    int32_t n_buildings;
    int32_t n_outline;
    const float *outline_x_m;          /* [n_outline] */
    const float *outline_y_m;          /* [n_outline] */
    const int16_t *outline_building;   /* [n_outline], each building's vertices consecutive, ≥ 3 */
    const int16_t *port_building;      /* [ports.n_ports], −1: outdoors */
    const int16_t *port_outdoor;       /* [ports.n_ports], 1: leads outdoors (GNSS on there) */
    const int16_t *port_steps;         /* [ports.n_ports], stairs: steps end to end (> 0); else 0 */
    const float *port_lo_x_m;          /* [ports.n_ports], the endpoint on floor_lo */
    const float *port_lo_y_m;
    const float *port_hi_x_m;          /* [ports.n_ports], the endpoint on floor_hi */
    const float *port_hi_y_m;
    int32_t n_links;
    const int32_t *link_a;             /* [n_links], 0 ≤ value < ports.n_ports */
    const int32_t *link_b;             /* [n_links] */
    int32_t n_contexts;
    const int16_t *kind;               /* [n_contexts], sf_context_* */
    const int16_t *building;           /* [n_contexts], −1 for the outdoor context */
    const int16_t *floor;              /* [n_contexts] */
    const int16_t *scheme;             /* [n_contexts], a fusion scheme (sf_scheme_*, < sf_scheme_count) */
    const int16_t *method;             /* [n_contexts], the absolute method it fuses (sf_fix_*) */
    const int16_t *cdd_method;         /* [n_contexts], sf_fix_wifi, sf_fix_ble or sf_fix_gnss */
    const int16_t *cdd_min_hits;       /* [n_contexts], ≥ 1 */
    int32_t n_cdd;
    const int16_t *cdd_context;        /* [n_cdd], non-decreasing, < n_contexts */
    const int64_t *cdd_id;             /* [n_cdd], AP BSSID or beacon id */
    const float *cdd_min_dbm;          /* [n_cdd] */
} sf_context_map_t;

/* Floors and frame of the site. */
typedef struct {
    double map_rotation_deg;
    int16_t lowest_floor;
    int32_t n_floors;
    const double *floor_height_m; /* [n_floors], strictly increasing */
    sf_fix_model_t fix_model;     /* measured fix errors, if the builder had held-out walks */
    sf_radiomap_t radiomap;       /* n_rp = 0: no radio map */
    sf_geo_ref_t geo;             /* not valid: GNSS fixes are not used */
    sf_floor_plan_t plan;         /* n_walls = 0: no walls */
    sf_ports_t ports;             /* n_ports = 0: floors change anywhere */
    sf_beacons_t beacons;         /* n_beacons = 0: BLE readings are not used */
    sf_context_map_t contexts;    /* n_contexts = 0: no multi-scheme controller */
} sf_site_t;

/* Checks every structural invariant above (sizes, orderings, index ranges, finite values).
 * Returns 0 (SF_OK) or SF_ERANGE; *what (may be NULL) points to a static text naming the first
 * violated invariant. Cost O(n_ap + n_rp + n_entries). */
int sf_radiomap_check(const sf_radiomap_t *map, const char **what);

/* Index of bssid in the AP table, or −1. O(log n_ap). */
int32_t sf_radiomap_find_ap(const sf_radiomap_t *map, int64_t bssid);

#endif
