/* sf_summary.c — stridefixd's exit summary on stderr (see sf_summary.h). */
#include "sf_summary.h"

#include <inttypes.h>

void sf_summary_print(FILE *const f, const sf_input_counters_t *const in, const sf_estimator_status_t *const est,
                      const sf_publish_sources_t *const src, const sf_lcm_out_counters_t *const oc,
                      const char *const log_path, const double wall_s)
{
    const sf_input_counters_t ic = *in;
    const sf_estimator_status_t st = *est;
    const sf_rx_counters_t *const c = &ic.rx;
    fprintf(f,
            "stridefixd: %" PRIu64 " frames (%" PRIu64 " ok): %" PRIu64 " bad syntax, %" PRIu64 " unknown id, %" PRIu64
            " truncated, %" PRIu64 " decode errors, %" PRIu64 " seq gaps, %" PRIu64 " unsynced, %" PRIu64
            " unpaired IMU halves, %" PRIu64 " incomplete scans, %" PRIu64 " CAN FD (of the unknown ids)\n",
            ic.frames_total, c->frames_ok, ic.bad_syntax, c->unknown_id, c->bad_length, c->decode_errors,
            c->seq_gaps, c->unsynced, c->imu_unpaired, c->wifi_incomplete, ic.can_fd);
    fprintf(f,
            "stridefixd: faults: %" PRIu64 " duplicates, %" PRIu64 " late, %" PRIu64 " corrupt seq, %" PRIu64
            " silences, %" PRIu64 " board restarts, %" PRIu64 " BOARD_TIME not believed, %" PRIu64
            " board time jumps; samples refused: %" PRIu32 " out of range, %" PRIu32 " jumps, %" PRIu32
            " out of order; %" PRIu32 " walk gaps bridged\n",
            c->duplicates, c->late, c->seq_rejected, c->silences, c->board_restarts, c->board_time_rejected,
            c->board_time_jumps, st.samples_out_of_range, st.samples_jumped, st.samples_out_of_order, st.gaps_bridged);
    fprintf(f,
            "stridefixd: %" PRIu64 " IMU, %" PRIu64 " MAG, %" PRIu64 " BARO, %" PRIu64 " WIFI, %" PRIu64
            " GNSS; %d steps; log %s: %" PRIu64 " events, %.2f MB, %" PRIu64 " dropped; %.2f s\n",
            c->imu, c->mag, c->baro, c->wifi, c->gnss, (int)st.step_count, log_path == NULL ? "(none)" : log_path,
            oc->events, (double)oc->bytes / 1e6, oc->drops, wall_s);
    fprintf(f,
            "stridefixd: sources: %" PRIu64 " BLE scans (%" PRIu64 " advertisements, %" PRIu64
            " dropped from full windows), %" PRIu64 " LANDMARK; fixes made of offered: Wi-Fi %" PRIu64
            " of %" PRIu64 ", GNSS %" PRIu64 " of %" PRIu64 ", BLE %" PRIu64 " of %" PRIu64 ", landmark %" PRIu64
            " of %" PRIu64 "\n",
            c->ble, c->ble_adverts, c->ble_dropped, c->landmark, src->made[sf_fix_wifi], src->offered[sf_fix_wifi],
            src->made[sf_fix_gnss], src->offered[sf_fix_gnss], src->made[sf_fix_ble], src->offered[sf_fix_ble],
            src->made[sf_fix_landmark], src->offered[sf_fix_landmark]);
    if (st.controller_active) {
        fprintf(f,
                "stridefixd: controller: %" PRIu32 " transitions, %" PRIu32 " context switches, %" PRIu32
                " stairs recalibrations, %" PRIu32 " source inputs kept off; radios on: GNSS %.1f s, Wi-Fi %.1f s,"
                " BLE %.1f s\n",
                st.context_transitions, st.context_switches, st.context_recalibrations, st.context_off, st.gnss_on_s,
                st.wifi_on_s, st.ble_on_s);
    }
    if (log_path != NULL) {
        fprintf(f,
                "stridefixd: log detail: %" PRIu64 " files, %" PRIu64 " events written (%" PRIu64
                " of them CONFIG copies heading a file: rotated, or after a full disk), %" PRIu64
                " bytes written; %" PRIu64 " events dropped, %" PRIu64 " bytes\n",
                oc->files, oc->events, oc->header_copies, oc->bytes, oc->drops, oc->drop_bytes);
    }
}

