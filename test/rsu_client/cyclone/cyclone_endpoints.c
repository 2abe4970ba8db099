/* What an independent DDS (Eclipse Cyclone, rmw_cyclonedds's middleware, its defaults) sees of the
 * other participants on the domain: every remote writer and reader with its topic, type, reliability
 * and durability, one line each, for SECONDS seconds (each endpoint printed once).
 *
 * usage: cyclone_endpoints SECONDS */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dds/dds.h"

#define MAX_SEEN 512
static char seen[MAX_SEEN][16];
static int n_seen = 0;

static int first_time(const dds_guid_t* key) {
  for (int i = 0; i < n_seen; ++i)
    if (memcmp(seen[i], key->v, 16) == 0) return 0;
  if (n_seen < MAX_SEEN) memcpy(seen[n_seen++], key->v, 16);
  return 1;
}

static void drain(dds_entity_t reader, const char* kind, const dds_guid_t* self) {
  void* samples[64] = {NULL};
  dds_sample_info_t infos[64];
  const int32_t n = dds_take(reader, samples, infos, 64, 64);
  for (int32_t i = 0; i < n; ++i) {
    const dds_builtintopic_endpoint_t* e = samples[i];
    if (!infos[i].valid_data || memcmp(e->participant_key.v, self->v, 12) == 0 || !first_time(&e->key)) continue;
    dds_reliability_kind_t reliability = DDS_RELIABILITY_BEST_EFFORT;
    dds_duration_t blocking = 0;
    dds_durability_kind_t durability = DDS_DURABILITY_VOLATILE;
    dds_qget_reliability(e->qos, &reliability, &blocking);
    dds_qget_durability(e->qos, &durability);
    printf("%s %s %s %s %s\n", kind, e->topic_name, e->type_name, reliability == DDS_RELIABILITY_RELIABLE ? "reliable" : "best_effort",
           durability == DDS_DURABILITY_TRANSIENT_LOCAL ? "transient_local" : durability == DDS_DURABILITY_VOLATILE ? "volatile" : "other");
  }
  if (n > 0) dds_return_loan(reader, samples, n);
  fflush(stdout);
}

int main(int argc, char** argv) {
  const double seconds = argc > 1 ? atof(argv[1]) : 10.0;
  const char* domain_text = getenv("ROS_DOMAIN_ID");
  const dds_domainid_t domain = domain_text && *domain_text ? (dds_domainid_t)atoi(domain_text) : 0;
  const dds_entity_t participant = dds_create_participant(domain, NULL, NULL);
  if (participant < 0) {
    fprintf(stderr, "cyclone: no participant: %s\n", dds_strretcode(-participant));
    return 1;
  }
  dds_guid_t self;
  dds_get_guid(participant, &self);
  const dds_entity_t writers = dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, NULL, NULL);
  const dds_entity_t readers = dds_create_reader(participant, DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, NULL, NULL);
  const dds_time_t end = dds_time() + (dds_duration_t)(seconds * 1e9);
  while (dds_time() < end) {
    drain(writers, "writer", &self);
    drain(readers, "reader", &self);
    dds_sleepfor(DDS_MSECS(100));
  }
  dds_delete(participant);
  return 0;
}
