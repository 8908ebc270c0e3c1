/* Force-included when building the OMG suite's Cyclone shape_main (srcC) against Cyclone DDS 11.0.1, which has
 * no dds_take_next_instance / dds_read_next_instance. Both are built here on dds_peek_with_collector: find the
 * smallest instance handle above `prev` among the samples the reader holds, then read or take that instance. */
#ifndef DDS_RS_CYCLONE_SHIM_H
#define DDS_RS_CYCLONE_SHIM_H
#include <dds/dds.h>

struct dds_rs_next_handle { dds_instance_handle_t prev, best; };

static dds_return_t dds_rs_collect_next (void *arg, const dds_sample_info_t *si,
                                         const struct ddsi_sertype *st, struct ddsi_serdata *sd)
{
  (void) st; (void) sd;
  struct dds_rs_next_handle *n = arg;
  if (si->instance_handle > n->prev && (n->best == 0 || si->instance_handle < n->best))
    n->best = si->instance_handle;
  return DDS_RETCODE_OK;
}

static dds_return_t dds_rs_next_instance (dds_entity_t rd, void **buf, dds_sample_info_t *si, size_t bufsz,
                                          uint32_t maxs, dds_instance_handle_t prev, bool take)
{
  struct dds_rs_next_handle n = { prev, 0 };
  dds_return_t rc = dds_peek_with_collector (rd, INT32_MAX, 0, 0, dds_rs_collect_next, &n);
  if (rc < 0)
    return rc;
  if (n.best == 0)
    return 0;
  return take ? dds_take_instance (rd, buf, si, bufsz, maxs, n.best)
              : dds_read_instance (rd, buf, si, bufsz, maxs, n.best);
}

#define dds_take_next_instance(rd, buf, si, bufsz, maxs, prev) \
  dds_rs_next_instance ((rd), (buf), (si), (bufsz), (maxs), (prev), true)
#define dds_read_next_instance(rd, buf, si, bufsz, maxs, prev) \
  dds_rs_next_instance ((rd), (buf), (si), (bufsz), (maxs), (prev), false)
#endif
