/* Throughput of Cyclone DDS 0.10 (Debian) over iceoryx shared memory, with writer and reader loans.
 *   iox_perf pub SIZE SECONDS [fill]   SIZE 1 or 4 (MiB); writes loaned samples for SECONDS
 *   iox_perf sub SIZE                  takes loaned samples, prints samples/s each second
 * The types come from bench.idl, compiled by Debian's /usr/bin/idlc (see scripts/bench-cyclone-iox.sh).
 * Cyclone 0.10.2 only puts a reader/writer on iceoryx when the type is fixed-size and the QoS is one
 * iceoryx can express: here KEEP_ALL history, MANUAL_BY_TOPIC liveliness or a finite deadline each kept it
 * off (see docs/performance.md, session 26). Both sides use RELIABLE, KEEP_LAST 16, VOLATILE, AUTOMATIC
 * liveliness; IOX_PERF_QOS changes one policy. Both print dds_is_shared_memory_available and
 * dds_is_loan_available, and the reader where its first loaned sample lies. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <stdint.h>
#include "dds/dds.h"
#include "dds/ddsc/dds_loan_api.h"
#include "bench.h"

#define DEPTH 16

static double now_s(void)
{
  struct timespec ts;
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return (double)ts.tv_sec + (double)ts.tv_nsec / 1e9;
}

static void check(dds_return_t rc, const char *what)
{
  if (rc < 0) {
    fprintf(stderr, "iox_perf: %s: %s\n", what, dds_strretcode(rc));
    exit(1);
  }
}

static dds_qos_t *bench_qos(void)
{
  dds_qos_t *qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(10));
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, DEPTH);
  dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
  dds_qset_liveliness(qos, DDS_LIVELINESS_AUTOMATIC, DDS_INFINITY);
  /* IOX_PERF_QOS changes one policy, to see which ones keep Cyclone off iceoryx. */
  const char *v = getenv("IOX_PERF_QOS");
  if (v && strcmp(v, "keep-all") == 0)
    dds_qset_history(qos, DDS_HISTORY_KEEP_ALL, 0);
  else if (v && strcmp(v, "keep-last-1000") == 0)
    dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1000);
  else if (v && strcmp(v, "transient-local") == 0)
    dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
  else if (v && strcmp(v, "manual-liveliness") == 0)
    dds_qset_liveliness(qos, DDS_LIVELINESS_MANUAL_BY_TOPIC, DDS_SECS(10));
  else if (v && strcmp(v, "deadline") == 0)
    dds_qset_deadline(qos, DDS_SECS(10));
  else if (v && strcmp(v, "best-effort") == 0)
    dds_qset_reliability(qos, DDS_RELIABILITY_BEST_EFFORT, 0);
  else if (v && *v) {
    fprintf(stderr, "iox_perf: IOX_PERF_QOS: keep-all, keep-last-1000, transient-local, manual-liveliness, deadline or best-effort\n");
    exit(2);
  }
  return qos;
}

/* Topic for SIZE (1 or 4 MiB); *data_len is the length of the octet array after `seq`. */
static dds_entity_t bench_topic(dds_entity_t pp, int size, size_t *data_len)
{
  const dds_topic_descriptor_t *desc = size == 4 ? &IoxBench_Plain4M_desc : &IoxBench_Plain1M_desc;
  *data_len = size == 4 ? sizeof(((IoxBench_Plain4M *)0)->data) : sizeof(((IoxBench_Plain1M *)0)->data);
  dds_entity_t tp = dds_create_topic(pp, desc, size == 4 ? "iox_perf_4m" : "iox_perf_1m", NULL, NULL);
  check(tp, "create_topic");
  return tp;
}

/* The writer (pub) or reader of the topic for `size`, with bench_qos(); says whether Cyclone put it on
 * shared memory and lends samples. */
static dds_entity_t bench_endpoint(dds_entity_t pp, int size, int pub, size_t *data_len)
{
  dds_entity_t tp = bench_topic(pp, size, data_len);
  dds_qos_t *qos = bench_qos();
  dds_entity_t e = pub ? dds_create_writer(pp, tp, qos, NULL) : dds_create_reader(pp, tp, qos, NULL);
  check(e, pub ? "create_writer" : "create_reader");
  dds_delete_qos(qos);
  fprintf(stderr, "%s: shared memory %s, loan %s\n", pub ? "pub" : "sub",
          dds_is_shared_memory_available(e) ? "yes" : "NO", dds_is_loan_available(e) ? "yes" : "NO");
  return e;
}

static int run_pub(dds_entity_t pp, int size, double secs, int fill)
{
  size_t data_len;
  dds_entity_t wr = bench_endpoint(pp, size, 1, &data_len);
  dds_publication_matched_status_t st = { 0 };
  double give_up = now_s() + 10.0;
  while (st.current_count == 0 && now_s() < give_up) {
    check(dds_get_publication_matched_status(wr, &st), "publication_matched");
    dds_sleepfor(DDS_MSECS(20));
  }
  if (st.current_count == 0) {
    fprintf(stderr, "pub: no reader matched in 10 s\n");
    return 1;
  }
  dds_sleepfor(DDS_MSECS(500)); /* let the reader's iceoryx subscription connect */
  uint64_t seq = 0, no_chunk = 0;
  double end = now_s() + secs;
  while (now_s() < end) {
    void *sample = NULL;
    /* With RouDi's pool exhausted (the reader's queue holds every chunk) the loan fails after
     * Cyclone's own retries: the writer waits by trying again. */
    if (dds_loan_sample(wr, &sample) != DDS_RETCODE_OK) {
      no_chunk++;
      continue;
    }
    uint64_t *s = sample; /* both types start with uint64 seq, then the octet array */
    s[0] = ++seq;
    if (fill)
      memset(s + 1, (int)(seq & 0xff), data_len);
    check(dds_write(wr, sample), "write");
  }
  fprintf(stderr, "pub: wrote %llu samples in %.1f s (%llu loans failed: no free chunk)\n", (unsigned long long)seq, secs,
          (unsigned long long)no_chunk);
  dds_sleepfor(DDS_MSECS(500));
  return 0;
}

/* Prints which mapping of this process holds ADDR (/proc/self/maps): a /dev/shm (iceoryx) segment means
 * the reader got the sample in place; the heap or an anonymous mapping means Cyclone copied it. */
static void where_is(const void *addr)
{
  FILE *f = fopen("/proc/self/maps", "r");
  char line[512];
  uintptr_t a = (uintptr_t)addr;
  while (f && fgets(line, sizeof line, f)) {
    unsigned long lo, hi;
    if (sscanf(line, "%lx-%lx", &lo, &hi) == 2 && a >= lo && a < hi) {
      const char *path = strchr(line, '/');
      fprintf(stderr, "sub: first loaned sample at %p, in %s", addr, path ? path : "an anonymous mapping (heap or malloc'd)\n");
      break;
    }
  }
  if (f)
    fclose(f);
}

struct sub_stats {
  uint64_t last_seq, received, lost, bad;
};

/* Takes whatever is available with reader loans; checks that seq increments. */
static void take_loans(dds_entity_t rd, struct sub_stats *st)
{
  void *buf[DEPTH] = { 0 };
  dds_sample_info_t info[DEPTH];
  dds_return_t n = dds_take(rd, buf, info, DEPTH, DEPTH);
  check(n, "take");
  for (dds_return_t i = 0; i < n; i++) {
    if (!info[i].valid_data)
      continue;
    if (st->received == 0)
      where_is(buf[i]);
    uint64_t seq = *(const uint64_t *)buf[i];
    if (seq <= st->last_seq)
      st->bad++;
    else
      st->lost += seq - st->last_seq - 1;
    st->last_seq = seq;
    st->received++;
  }
  if (n > 0)
    check(dds_return_loan(rd, buf, n), "return_loan");
}

static int run_sub(dds_entity_t pp, int size)
{
  size_t data_len;
  dds_entity_t rd = bench_endpoint(pp, size, 0, &data_len);
  dds_entity_t ws = dds_create_waitset(pp);
  dds_entity_t rc = dds_create_readcondition(rd, DDS_ANY_STATE);
  check(dds_waitset_attach(ws, rc, 0), "waitset_attach");
  struct sub_stats st = { 0 };
  double start = 0, tick = 0, idle_since = now_s();
  uint64_t at_tick = 0, at_start = 0;
  while (now_s() - idle_since < (st.received ? 2.0 : 30.0)) {
    uint64_t before = st.received;
    dds_waitset_wait(ws, NULL, 0, DDS_MSECS(100));
    take_loans(rd, &st);
    double t = now_s();
    if (st.received != before)
      idle_since = t;
    if (before == 0 && st.received > 0)
    {
      start = tick = t;
      at_tick = at_start = st.received;
    }
    if (start > 0 && t - tick >= 1.0 && st.received != before) {
      printf("%.0f samples/s\n", (double)(st.received - at_tick) / (t - tick));
      fflush(stdout);
      at_tick = st.received;
      tick = t;
    }
  }
  double span = tick - start;
  printf("mean %.0f samples/s over %.1f s; received %llu, lost %llu, out of order %llu, last seq %llu\n",
         span > 0 ? (double)(at_tick - at_start) / span : 0.0, span, (unsigned long long)st.received,
         (unsigned long long)st.lost, (unsigned long long)st.bad, (unsigned long long)st.last_seq);
  return st.received > 0 ? 0 : 1;
}

int main(int argc, char **argv)
{
  if (argc < 3 || (strcmp(argv[1], "pub") != 0 && strcmp(argv[1], "sub") != 0) || (strcmp(argv[1], "pub") == 0 && argc < 4)) {
    fprintf(stderr, "usage: iox_perf pub SIZE SECONDS [fill] | iox_perf sub SIZE   (SIZE: 1 or 4 MiB)\n");
    return 2;
  }
  int size = atoi(argv[2]);
  if (size != 1 && size != 4) {
    fprintf(stderr, "iox_perf: SIZE must be 1 or 4 (MiB)\n");
    return 2;
  }
  dds_entity_t pp = dds_create_participant(DDS_DOMAIN_DEFAULT, NULL, NULL);
  check(pp, "create_participant");
  int rc = strcmp(argv[1], "pub") == 0 ? run_pub(pp, size, atof(argv[3]), argc > 4 && strcmp(argv[4], "fill") == 0)
                                       : run_sub(pp, size);
  dds_delete(pp);
  return rc;
}
