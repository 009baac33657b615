/* cyclone_reader: the foreign vendor's view of Telltale's wire (idl/README.md, "Another vendor").
 *
 * An Eclipse Cyclone DDS subscriber to every Telltale topic, built from the types Cyclone's own
 * idlc generates from idl/telltale.idl (C, at build time). It joins a domain, prints the first
 * samples of every topic with their decoded fields, a count per topic every second, and a final
 * count when it stops (SIGINT, SIGTERM or --seconds). The interop test (tests/interop/
 * interop_test.cpp) reads these lines; a person can run it by hand against a running fleet:
 *
 *   CYCLONEDDS_URI=file://$PWD/tests/interop/cyclone_loopback.xml \
 *     build/bin/cyclone_reader --domain 0 --seconds 10
 *
 * Output lines (one per line, fields key=value, texts in double quotes):
 *   cyclone_reader ready: domain=D topics=10
 *   matched topic=T writers=N               when the number of matched writers changes
 *   incompatible topic=T policy=NAME count=N a writer was refused (a QoS or representation clash)
 *   sample topic=T field=value ...           the first --print samples of each topic
 *   counts T=N T=N ...                       every second
 *   cyclone_reader stopped: T=N T=N ...      at the end
 *
 * Reader QoS: best effort for the best-effort topics (accepts any writer); reliable for both
 * backfills (attitude and fixes); reliable + transient local for status, alarm rules and alarm
 * events (their writers keep the latest per instance for late joiners). No deadline or
 * liveliness: a reader without them matches any writer.
 */
#include <inttypes.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "dds/dds.h"
#include "telltale.h"

static volatile sig_atomic_t stop_requested = 0;
static void on_signal(int signo) {
  (void)signo;
  stop_requested = 1;
}

/* A text in double quotes, with quotes, backslashes and control characters escaped. */
static void print_text(const char* key, const char* s) {
  printf(" %s=\"", key);
  for (const unsigned char* p = (const unsigned char*)s; *p; ++p) {
    if (*p == '"' || *p == '\\')
      printf("\\%c", *p);
    else if (*p < 0x20 || *p == 0x7f)
      printf("\\x%02x", *p);
    else
      putchar(*p);
  }
  putchar('"');
}

static void print_attitude(const void* v) {
  const telltale_msg_BoatAttitude* m = v;
  printf(
      " boat_id=%s seq=%" PRIu64 " t_utc_ns=%" PRIu64
      " heel_deg=%.6f pitch_deg=%.6f heading_deg=%.6f heel_rate_deg_s=%.6f"
      " yaw_rate_deg_s=%.6f accel_weight=%.6f quality=%.6f led_count=%u level=%d boot_id=%" PRIu64,
      m->boat_id, m->seq, m->t_utc_ns, m->heel_deg, m->pitch_deg, m->heading_deg,
      m->heel_rate_deg_s, m->yaw_rate_deg_s, (double)m->accel_weight, (double)m->quality,
      (unsigned)m->leds.led_count, (int)m->leds.level, m->boot_id);
}

static void print_ack(const void* v) {
  const telltale_msg_ShoreAck* m = v;
  printf(" boat_id=%s boot_id=%" PRIu64 " acked_seq=%" PRIu64 " t_utc_ns=%" PRIu64, m->boat_id,
         m->boot_id, m->acked_seq, m->t_utc_ns);
}

static void print_status(const void* v) {
  const telltale_msg_NodeStatus* m = v;
  printf(" node_id=%s kind=%d", m->node_id, (int)m->kind);
  print_text("software_version", m->software_version);
  printf(" t_utc_ns=%" PRIu64 " uptime_s=%.3f sensor_health=%" PRIu32, m->t_utc_ns, m->uptime_s,
         m->sensor_health);
  print_text("health_text", m->health_text);
  printf(" samples_published=%" PRIu64, m->samples_published);
  print_text("group", m->group);
}

static void print_rule(const void* v) {
  const telltale_msg_AlarmRule* m = v;
  printf(" rule_id=%s", m->rule_id);
  print_text("scope", m->scope);
  printf(
      " quantity=%d min_deg=%.6f max_deg=%.6f hold_s=%.6f hysteresis_deg=%.6f level=%d"
      " enabled=%d revision=%" PRIu64,
      (int)m->quantity, m->min_deg, m->max_deg, m->hold_s, m->hysteresis_deg, (int)m->level,
      m->enabled ? 1 : 0, m->revision);
}

static void print_event(const void* v) {
  const telltale_msg_AlarmEvent* m = v;
  printf(" boat_id=%s rule_id=%s event_id=%" PRIu64 " t_utc_ns=%" PRIu64
         " level=%d phase=%d value_deg=%.6f",
         m->boat_id, m->rule_id, m->event_id, m->t_utc_ns, (int)m->level, (int)m->phase,
         m->value_deg);
  print_text("message", m->message);
}

static void print_wearable(const void* v) {
  const telltale_msg_WearableMotion* m = v;
  printf(" athlete_id=%s seq=%" PRIu64 " t_utc_ns=%" PRIu64 " steps=%" PRIu32
         " cadence_spm=%.6f gait=%d pose=%d x_m=%.6f y_m=%.6f heading_deg=%.6f distance_m=%.6f",
         m->athlete_id, m->seq, m->t_utc_ns, m->steps, m->cadence_spm, (int)m->gait, (int)m->pose,
         m->x_m, m->y_m, m->heading_deg, m->distance_m);
}

static void print_fix(const void* v) {
  const telltale_msg_BoatFix* m = v;
  printf(" boat_id=%s seq=%" PRIu64 " t_utc_ns=%" PRIu64 " gnss_utc_ns=%" PRIu64
         " lat_deg=%.9f lon_deg=%.9f sog_m_s=%.6f cog_deg=%.6f fix=%d satellites=%u hdop=%.6f"
         " boot_id=%" PRIu64,
         m->boat_id, m->seq, m->t_utc_ns, m->gnss_utc_ns, m->lat_deg, m->lon_deg, m->sog_m_s,
         m->cog_deg, (int)m->fix, (unsigned)m->satellites, (double)m->hdop, m->boot_id);
}

static void print_wind(const void* v) {
  const telltale_msg_BoatWind* m = v;
  printf(" boat_id=%s seq=%" PRIu64 " t_utc_ns=%" PRIu64 " from_deg=%.6f speed_m_s=%.6f",
         m->boat_id, m->seq, m->t_utc_ns, m->from_deg, m->speed_m_s);
  print_text("source", m->source);
  printf(" boot_id=%" PRIu64, m->boot_id);
}

enum Durable { kVolatileBestEffort, kVolatileReliable, kTransientLocalReliable };

struct TopicSpec {
  const char* name;
  const dds_topic_descriptor_t* desc;
  enum Durable qos;
  void (*print)(const void*);
  /* state */
  dds_entity_t reader;
  uint64_t count;
  int printed;
  uint32_t matched;
  uint32_t incompatible;
};

/* The topic names of idl/runtime/dds_participant.hpp (the C side cannot include it). */
static struct TopicSpec topics[] = {
    {"telltale_boat_attitude", &telltale_msg_BoatAttitude_desc, kVolatileBestEffort, print_attitude,
     0, 0, 0, 0, 0},
    {"telltale_boat_backfill", &telltale_msg_BoatAttitude_desc, kVolatileReliable, print_attitude,
     0, 0, 0, 0, 0},
    {"telltale_shore_ack", &telltale_msg_ShoreAck_desc, kVolatileBestEffort, print_ack, 0, 0, 0, 0,
     0},
    {"telltale_node_status", &telltale_msg_NodeStatus_desc, kTransientLocalReliable, print_status,
     0, 0, 0, 0, 0},
    {"telltale_alarm_rules", &telltale_msg_AlarmRule_desc, kTransientLocalReliable, print_rule, 0,
     0, 0, 0, 0},
    {"telltale_alarm_events", &telltale_msg_AlarmEvent_desc, kTransientLocalReliable, print_event,
     0, 0, 0, 0, 0},
    {"telltale_wearable_motion", &telltale_msg_WearableMotion_desc, kVolatileBestEffort,
     print_wearable, 0, 0, 0, 0, 0},
    {"telltale_boat_fix", &telltale_msg_BoatFix_desc, kVolatileBestEffort, print_fix, 0, 0, 0, 0,
     0},
    {"telltale_boat_fix_backfill", &telltale_msg_BoatFix_desc, kVolatileReliable, print_fix, 0, 0,
     0, 0, 0},
    {"telltale_shore_fix_ack", &telltale_msg_ShoreAck_desc, kVolatileBestEffort, print_ack, 0, 0, 0,
     0, 0},
    {"telltale_boat_wind", &telltale_msg_BoatWind_desc, kVolatileBestEffort, print_wind, 0, 0, 0, 0,
     0},
};
enum { kTopicCount = sizeof topics / sizeof topics[0] };

static const char* policy_name(uint32_t id) {
  switch (id) {
    case DDS_DURABILITY_QOS_POLICY_ID:
      return "durability";
    case DDS_DEADLINE_QOS_POLICY_ID:
      return "deadline";
    case DDS_LIVELINESS_QOS_POLICY_ID:
      return "liveliness";
    case DDS_RELIABILITY_QOS_POLICY_ID:
      return "reliability";
    case DDS_PARTITION_QOS_POLICY_ID:
      return "partition";
    case DDS_OWNERSHIP_QOS_POLICY_ID:
      return "ownership";
    case DDS_DESTINATIONORDER_QOS_POLICY_ID:
      return "destination_order";
    case DDS_PRESENTATION_QOS_POLICY_ID:
      return "presentation";
    case DDS_LATENCYBUDGET_QOS_POLICY_ID:
      return "latency_budget";
    case DDS_TYPE_CONSISTENCY_ENFORCEMENT_QOS_POLICY_ID:
      return "type_consistency";
    case DDS_DATA_REPRESENTATION_QOS_POLICY_ID:
      return "data_representation";
    default:
      return "other";
  }
}

static void print_counts(const char* head) {
  printf("%s", head);
  for (int i = 0; i < kTopicCount; ++i) printf(" %s=%" PRIu64, topics[i].name, topics[i].count);
  printf("\n");
  fflush(stdout);
}

static void poll_status(struct TopicSpec* t) {
  dds_subscription_matched_status_t sm;
  if (dds_get_subscription_matched_status(t->reader, &sm) == DDS_RETCODE_OK &&
      sm.current_count != t->matched) {
    t->matched = sm.current_count;
    printf("matched topic=%s writers=%" PRIu32 "\n", t->name, t->matched);
  }
  dds_requested_incompatible_qos_status_t iq;
  if (dds_get_requested_incompatible_qos_status(t->reader, &iq) == DDS_RETCODE_OK &&
      iq.total_count != t->incompatible) {
    t->incompatible = iq.total_count;
    printf("incompatible topic=%s policy=%s count=%" PRIu32 "\n", t->name,
           policy_name(iq.last_policy_id), iq.total_count);
  }
}

static void take_all(struct TopicSpec* t, int print_limit) {
  enum { kBatch = 64 };
  void* samples[kBatch];
  dds_sample_info_t infos[kBatch];
  for (;;) {
    memset(samples, 0, sizeof samples);
    const dds_return_t n = dds_take(t->reader, samples, infos, kBatch, kBatch);
    if (n <= 0) return;
    for (dds_return_t i = 0; i < n; ++i) {
      if (!infos[i].valid_data) continue;
      ++t->count;
      if (print_limit < 0 || t->printed < print_limit) {
        ++t->printed;
        printf("sample topic=%s", t->name);
        t->print(samples[i]);
        printf("\n");
      }
    }
    dds_return_loan(t->reader, samples, n);
    if (n < kBatch) return;
  }
}

static void usage(const char* argv0) {
  fprintf(stderr,
          "usage: %s --domain D [--seconds N] [--print K]\n"
          "  --domain D   DDS domain id (the Telltale nodes' --domain)\n"
          "  --seconds N  stop after N seconds (default: at SIGINT / SIGTERM)\n"
          "  --print K    print the first K samples of each topic (default 5; -1: all)\n"
          "Cyclone's configuration comes from CYCLONEDDS_URI (tests/interop/"
          "cyclone_loopback.xml: loopback only, unicast discovery).\n",
          argv0);
}

int main(int argc, char** argv) {
  long domain = -1;
  double seconds = -1.0;
  int print_limit = 5;
  for (int i = 1; i < argc; ++i) {
    if (strcmp(argv[i], "--domain") == 0 && i + 1 < argc) {
      domain = strtol(argv[++i], NULL, 10);
    } else if (strcmp(argv[i], "--seconds") == 0 && i + 1 < argc) {
      seconds = strtod(argv[++i], NULL);
    } else if (strcmp(argv[i], "--print") == 0 && i + 1 < argc) {
      print_limit = (int)strtol(argv[++i], NULL, 10);
    } else {
      usage(argv[0]);
      return 2;
    }
  }
  if (domain < 0 || domain > 232) {
    usage(argv[0]);
    return 2;
  }
  setvbuf(stdout, NULL, _IOLBF, 0);
  struct sigaction sa;
  memset(&sa, 0, sizeof sa);
  sa.sa_handler = on_signal;
  sigaction(SIGINT, &sa, NULL);
  sigaction(SIGTERM, &sa, NULL);

  const dds_entity_t participant = dds_create_participant((dds_domainid_t)domain, NULL, NULL);
  if (participant < 0) {
    fprintf(stderr, "cyclone_reader: dds_create_participant: %s\n", dds_strretcode(-participant));
    return 1;
  }
  const dds_entity_t waitset = dds_create_waitset(participant);
  for (int i = 0; i < kTopicCount; ++i) {
    struct TopicSpec* t = &topics[i];
    const dds_entity_t topic = dds_create_topic(participant, t->desc, t->name, NULL, NULL);
    if (topic < 0) {
      fprintf(stderr, "cyclone_reader: dds_create_topic %s: %s\n", t->name, dds_strretcode(-topic));
      dds_delete(participant);
      return 1;
    }
    dds_qos_t* qos = dds_create_qos();
    switch (t->qos) {
      case kVolatileBestEffort:
        dds_qset_reliability(qos, DDS_RELIABILITY_BEST_EFFORT, 0);
        dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
        dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 64);
        break;
      case kVolatileReliable:
        dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
        dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
        dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 5000);
        break;
      case kTransientLocalReliable:
        dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, DDS_SECS(1));
        dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
        dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 16);
        break;
    }
    t->reader = dds_create_reader(participant, topic, qos, NULL);
    dds_delete_qos(qos);
    if (t->reader < 0) {
      fprintf(stderr, "cyclone_reader: dds_create_reader %s: %s\n", t->name,
              dds_strretcode(-t->reader));
      dds_delete(participant);
      return 1;
    }
    dds_set_status_mask(t->reader, DDS_DATA_AVAILABLE_STATUS);
    dds_waitset_attach(waitset, t->reader, (dds_attach_t)i);
  }
  printf("cyclone_reader ready: domain=%ld topics=%d\n", domain, (int)kTopicCount);

  struct timespec start;
  struct timespec last_counts;
  clock_gettime(CLOCK_MONOTONIC, &start);
  last_counts = start;
  while (!stop_requested) {
    dds_attach_t triggered[kTopicCount];
    (void)dds_waitset_wait(waitset, triggered, kTopicCount, DDS_MSECS(100));
    for (int i = 0; i < kTopicCount; ++i) take_all(&topics[i], print_limit);
    struct timespec now;
    clock_gettime(CLOCK_MONOTONIC, &now);
    const double since_counts = (double)(now.tv_sec - last_counts.tv_sec) +
                                (double)(now.tv_nsec - last_counts.tv_nsec) * 1e-9;
    if (since_counts >= 1.0) {
      for (int i = 0; i < kTopicCount; ++i) poll_status(&topics[i]);
      print_counts("counts");
      last_counts = now;
    }
    const double elapsed =
        (double)(now.tv_sec - start.tv_sec) + (double)(now.tv_nsec - start.tv_nsec) * 1e-9;
    if (seconds >= 0.0 && elapsed >= seconds) break;
  }
  for (int i = 0; i < kTopicCount; ++i) {
    take_all(&topics[i], print_limit);
    poll_status(&topics[i]);
  }
  print_counts("cyclone_reader stopped:");
  dds_delete(participant);
  return 0;
}
