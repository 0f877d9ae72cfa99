/* test_log_ring.c — sf_log_ring against a dumb reference model (a FIFO of copies): seeded random
 * reservations of every size up to a quarter of the ring, commits and cancels, takes of all or of a
 * few events and releases, interleaved as a producer and a writer would; every taken event is the
 * model's next, byte for byte, in a valid log layout; the queued counts and bytes agree; the ring
 * never hands out room it has not got back (an event is never overwritten before it is released). */
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <setjmp.h>
#include <cmocka.h>

#include <stdio.h>
#include <string.h>

#include "sf_error.h"
#include "sf_log_file.h"
#include "sf_log_ring.h"
#include "sf_test_rng.h"

#define RING_BYTES 4096
#define MODEL_MAX 512
#define STEPS 200000

typedef struct {
    int64_t t_us;
    char channel[8];
    size_t size;
    uint8_t fill; /* data byte i is fill + i */
    bool header;
} model_event_t;

typedef struct {
    model_event_t q[MODEL_MAX];
    size_t first, n; /* queued, oldest first */
    size_t queued_bytes;
} model_t;

static size_t event_bytes(const model_event_t *const m)
{
    return SF_LOG_FILE_EVENT_OVERHEAD + strlen(m->channel) + m->size;
}

static unsigned pick(rng_t *const r, const unsigned n)
{
    return (unsigned)(rng_uniform01(r) * n);
}

/* Checks one taken event against the model's oldest and pops it; the event's bytes. */
static size_t check_event(model_t *const model, const uint8_t *const e)
{
    assert_true(model->n > 0);
    const model_event_t *const m = &model->q[model->first];
    const size_t channel_len = strlen(m->channel);
    uint8_t head[SF_LOG_FILE_EVENT_OVERHEAD];
    sf_log_file_put_header(head, m->header ? SF_LOG_RING_HEADER : 0, m->t_us, channel_len, m->size);
    assert_memory_equal(e, head, sizeof head);
    assert_int_equal(sf_log_ring_flags(e), m->header ? SF_LOG_RING_HEADER : 0u);
    assert_memory_equal(e + sizeof head, m->channel, channel_len);
    const uint8_t *const data = e + sizeof head + channel_len;
    for (size_t i = 0; i < m->size; i++) {
        assert_int_equal(data[i], (uint8_t)(m->fill + i));
    }
    const size_t bytes = event_bytes(m);
    assert_int_equal(sf_log_file_event_bytes(e), bytes);
    model->queued_bytes -= bytes;
    model->first = (model->first + 1) % MODEL_MAX;
    model->n--;
    return bytes;
}

static void test_ring_matches_a_fifo_of_copies(void **state)
{
    (void)state;
    sf_log_ring_t ring;
    assert_int_equal(sf_log_ring_init(&ring, RING_BYTES), SF_OK);
    model_t model = {0};
    rng_t rng = {0x5eed1234abcdULL};
    size_t in_flight = 0; /* bytes taken, not yet released */
    sf_log_ring_run_t taken_runs[2];
    int n_taken_runs = 0;
    static uint8_t copy[RING_BYTES]; /* the taken bytes as taken */
    uint64_t reserved = 0, refused = 0, taken = 0;
    for (int step = 0; step < STEPS; step++) {
        const unsigned what = pick(&rng, 10);
        if (what < 6 && model.n < MODEL_MAX) { /* the producer: one event */
            model_event_t m = {.t_us = (int64_t)step * 1000 - 5, .fill = (uint8_t)pick(&rng, 256),
                               .header = pick(&rng, 50) == 0};
            snprintf(m.channel, sizeof m.channel, "%.*s", 1 + (int)pick(&rng, 6), "ABCDEFG");
            m.size = pick(&rng, 8) == 0 ? pick(&rng, RING_BYTES / 4 - 40) : pick(&rng, 120);
            const size_t bytes = event_bytes(&m);
            uint8_t *const p = sf_log_ring_reserve(&ring, m.channel, strlen(m.channel), m.t_us, m.size,
                                                   m.header ? SF_LOG_RING_HEADER : 0u);
            /* never refused while the ring holds less than a quarter: room must come back */
            if (p == NULL) {
                refused++;
                assert_true(model.queued_bytes + in_flight + bytes > RING_BYTES / 4);
                continue;
            }
            reserved++;
            assert_true(p >= ring.buf && p + m.size <= ring.buf + ring.size);
            for (size_t i = 0; i < m.size; i++) {
                p[i] = (uint8_t)(m.fill + i);
            }
            const bool commit = pick(&rng, 20) != 0;
            sf_log_ring_commit(&ring, commit);
            if (commit) {
                model.q[(model.first + model.n) % MODEL_MAX] = m;
                model.n++;
                model.queued_bytes += bytes;
            }
        } else if (what < 9 && !ring.taking) { /* the writer takes all, or a few */
            const uint64_t max = pick(&rng, 3) == 0 ? 1 + pick(&rng, 4) : UINT64_MAX;
            sf_log_ring_run_t runs[2];
            uint64_t n = 0;
            const int n_runs = sf_log_ring_take(&ring, max, runs, &n);
            assert_true(n <= max && n <= model.n + 0u);
            uint64_t seen = 0;
            in_flight = 0;
            for (int k = 0; k < n_runs; k++) {
                assert_true(runs[k].len > 0);
                for (size_t at = 0; at < runs[k].len; seen++) {
                    at += check_event(&model, runs[k].p + at);
                }
                memcpy(copy + in_flight, runs[k].p, runs[k].len);
                in_flight += runs[k].len;
                taken_runs[k] = runs[k];
            }
            n_taken_runs = n_runs;
            assert_int_equal(seen, n);
            taken += n;
        } else if (ring.taking) { /* the writer is done with what it took */
            /* what it took is intact until now: no reservation since reached into it */
            size_t at = 0;
            for (int k = 0; k < n_taken_runs; k++) {
                assert_memory_equal(taken_runs[k].p, copy + at, taken_runs[k].len);
                at += taken_runs[k].len;
            }
            sf_log_ring_release(&ring);
            in_flight = 0;
        }
        assert_int_equal(ring.queued, model.n);
        assert_int_equal(sf_log_ring_queued_bytes(&ring), model.queued_bytes);
    }
    assert_true(reserved > STEPS / 3 && refused > 0 && taken > STEPS / 4);
    sf_log_ring_free(&ring);
}

/* An empty ring starts again at the buffer's beginning: a replay that drains each batch touches only
 * the first batch's pages. */
static void test_empty_ring_restarts_at_the_beginning(void **state)
{
    (void)state;
    sf_log_ring_t ring;
    assert_int_equal(sf_log_ring_init(&ring, RING_BYTES), SF_OK);
    for (int i = 0; i < 100; i++) {
        uint8_t *const p = sf_log_ring_reserve(&ring, "IMU", 3, i, 64, 0);
        assert_ptr_equal(p, ring.buf + SF_LOG_FILE_EVENT_OVERHEAD + 3);
        sf_log_ring_commit(&ring, true);
        sf_log_ring_run_t runs[2];
        uint64_t n;
        assert_int_equal(sf_log_ring_take(&ring, UINT64_MAX, runs, &n), 1);
        assert_int_equal(n, 1);
        sf_log_ring_release(&ring);
    }
    sf_log_ring_free(&ring);
}

int main(void)
{
    const struct CMUnitTest tests[] = {
        cmocka_unit_test(test_ring_matches_a_fifo_of_copies),
        cmocka_unit_test(test_empty_ring_restarts_at_the_beginning),
    };
    return cmocka_run_group_tests(tests, NULL, NULL);
}
