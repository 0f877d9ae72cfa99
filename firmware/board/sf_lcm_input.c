/* sf_lcm_input.c — raw-sensor LCM log → sf_rx_event_t (see sf_lcm_input.h). */
#include "sf_lcm_input.h"

#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <lcm/eventlog.h>

#include "sf_error.h"
#include "stridefix_baro_t.h"
#include "stridefix_gnss_t.h"
#include "stridefix_imu_t.h"
#include "stridefix_mag_t.h"
#include "stridefix_wifi_scan_t.h"

struct sf_lcm_input {
    lcm_eventlog_t *log;
    sf_lcm_input_counters_t counters;
};

int sf_lcm_input_open(sf_lcm_input_t **const result, const char *const path, char *const err, const size_t err_size)
{
    sf_lcm_input_t *const in = calloc(1, sizeof *in);
    if (in == NULL) {
        snprintf(err, err_size, "out of memory");
        return SF_EIO;
    }
    FILE *const probe = fopen(path, "rb");
    if (probe == NULL) {
        const int e = errno;
        snprintf(err, err_size, "%s: cannot open: %s", path, strerror(e));
        free(in);
        return e == ENOENT ? SF_ENOENT : SF_EIO;
    }
    fclose(probe);
    in->log = lcm_eventlog_create(path, "r");
    if (in->log == NULL) {
        snprintf(err, err_size, "%s: cannot open as an LCM log", path);
        free(in);
        return SF_EIO;
    }
    *result = in;
    return SF_OK;
}

static int decode_wifi(const lcm_eventlog_event_t *const e, sf_rx_event_t *const ev)
{
    stridefix_wifi_scan_t m;
    if (stridefix_wifi_scan_t_decode(e->data, 0, e->datalen, &m) < 0) {
        return SF_ESYNTAX;
    }
    sf_rx_wifi_t *const w = &ev->u.wifi;
    w->t_us = m.t_us;
    w->scan_id = m.scan_id;
    w->complete = m.complete != 0;
    w->n_ap = m.n_ap < SF_WIFI_MAX_AP ? m.n_ap : SF_WIFI_MAX_AP; /* the rest cannot be used anyway */
    for (int32_t i = 0; i < w->n_ap; i++) {
        w->bssid[i] = m.bssid[i];
        w->rssi_dbm[i] = m.rssi_dbm[i];
        w->freq_mhz[i] = m.freq_mhz[i];
    }
    stridefix_wifi_scan_t_decode_cleanup(&m);
    ev->kind = sf_rx_wifi;
    return 1;
}

/* Decodes one event; 1 a sensor event, 0 another channel, SF_ESYNTAX a bad payload. */
static int decode(const lcm_eventlog_event_t *const e, sf_rx_event_t *const ev)
{
    const char *const ch = e->channel;
    if (strcmp(ch, "IMU") == 0) {
        stridefix_imu_t m;
        if (stridefix_imu_t_decode(e->data, 0, e->datalen, &m) < 0) {
            return SF_ESYNTAX;
        }
        ev->kind = sf_rx_imu;
        ev->u.imu.t_us = m.t_us;
        ev->u.imu.seq = m.seq;
        memcpy(ev->u.imu.accel_mps2, m.accel_mps2, sizeof m.accel_mps2);
        memcpy(ev->u.imu.gyro_radps, m.gyro_radps, sizeof m.gyro_radps);
        return 1;
    }
    if (strcmp(ch, "MAG") == 0) {
        stridefix_mag_t m;
        if (stridefix_mag_t_decode(e->data, 0, e->datalen, &m) < 0) {
            return SF_ESYNTAX;
        }
        ev->kind = sf_rx_mag;
        ev->u.mag.t_us = m.t_us;
        ev->u.mag.seq = m.seq;
        memcpy(ev->u.mag.field_ut, m.field_ut, sizeof m.field_ut);
        return 1;
    }
    if (strcmp(ch, "BARO") == 0) {
        stridefix_baro_t m;
        if (stridefix_baro_t_decode(e->data, 0, e->datalen, &m) < 0) {
            return SF_ESYNTAX;
        }
        ev->kind = sf_rx_baro;
        ev->u.baro = (sf_rx_baro_t){m.t_us, m.seq, m.pressure_pa, m.temperature_degc};
        return 1;
    }
    if (strcmp(ch, "GNSS") == 0) {
        stridefix_gnss_t m;
        if (stridefix_gnss_t_decode(e->data, 0, e->datalen, &m) < 0) {
            return SF_ESYNTAX;
        }
        ev->kind = sf_rx_gnss;
        ev->u.gnss = (sf_rx_gnss_t){m.t_us, m.lat_deg, m.lon_deg, m.alt_m, m.accuracy_m};
        return 1;
    }
    if (strcmp(ch, "WIFI") == 0) {
        return decode_wifi(e, ev);
    }
    return 0;
}

int sf_lcm_input_next(sf_lcm_input_t *const in, sf_rx_event_t *const ev, int64_t *const log_t_us)
{
    for (;;) {
        lcm_eventlog_event_t *const e = lcm_eventlog_read_next_event(in->log);
        if (e == NULL) {
            return 0;
        }
        in->counters.events++;
        const int rc = decode(e, ev);
        *log_t_us = e->timestamp;
        lcm_eventlog_free_event(e);
        if (rc == 1) {
            in->counters.used++;
            return 1;
        }
        if (rc < 0) {
            in->counters.decode_errors++;
            return SF_ESYNTAX;
        }
        in->counters.other_channels++;
    }
}

void sf_lcm_input_counters(const sf_lcm_input_t *const in, sf_lcm_input_counters_t *const counters)
{
    *counters = in->counters;
}

void sf_lcm_input_close(sf_lcm_input_t *const in)
{
    if (in != NULL) {
        lcm_eventlog_destroy(in->log);
        free(in);
    }
}
