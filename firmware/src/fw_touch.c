/* fw_touch.c - calibration by touching (fw_touch.h). */
#include "dhcal_fw/fw_touch.h"

#if DHC_WITH_CONTACT

#include <math.h>
#include <string.h>

#include "dhcal/dhc_geometry.h"
#include "dhcal_fw/fw_ik.h"

void fw_touch_default_config(fw_touch_config *cfg)
{
    memset(cfg, 0, sizeof *cfg);
    cfg->per_plane = 20U;
    cfg->per_gauge = 6U;
    cfg->standoff_mm = 5.0;
    cfg->overtravel_mm = 5.0;
    cfg->clearance_mm = 40.0;
    cfg->speed_mm_s = 2.0;
    cfg->seed = 2828U;
}

/* A low-discrepancy point in [-1, 1) (Halton, base b): the touches cover their region evenly,
 * the same ones for the same seed. */
static double halton(uint32_t index, uint32_t base)
{
    double f = 1.0;
    double r = 0.0;
    for (uint32_t i = index; i > 0U; i /= base) {
        f /= (double)base;
        r += f * (double)(i % base);
    }
    return 2.0 * r - 1.0;
}

static void along(const double p[3], double s, const double d[3], double out[3])
{
    for (size_t k = 0U; k < 3U; ++k) {
        out[k] = p[k] + s * d[k];
    }
}

/* Joint angles that put the tool at x (in: a seed, when seeded), on the model. Arms shaped like
 * the paper's start from its closed form on one of four branches: bit 0 the elbow, bit 1 the
 * shoulder turned half a turn with the upper arm leaning back over the base axis (the same
 * point, the arm's sideways offsets mirrored: what tells them from a turn of the base). */
static int reach(const dhc_model *model, const double x[3], unsigned branch, int seeded,
                 double q[DHC_MAX_JOINTS])
{
    if (!seeded) {
        memset(q, 0, DHC_MAX_JOINTS * sizeof q[0]);
        if (model->arm.n_joints == 3U) {
            (void)fw_ik_seed_3dof(model, x, (int)(branch & 1U), q);
            if ((branch & 2U) != 0U) {
                q[0] += q[0] > 0.0 ? -DHC_PI : DHC_PI;
                q[1] = DHC_PI - q[1] - 2.0 * model->arm.joint[1].theta_offset_rad;
                q[2] = -q[2] - 2.0 * model->arm.joint[2].theta_offset_rad;
            }
        } else {
            for (size_t j = 0U; j < model->arm.n_joints; ++j) {
                q[j] = 0.5 * (model->arm.joint[j].min_rad + model->arm.joint[j].max_rad);
            }
        }
    }
    dhc_sample tmpl;
    dhc_model_sample_at(model, q, NULL, DHC_MEAS_POSITION, &tmpl);
    return fw_ik_solve(model, &tmpl, x, 1e-4, 100U, q) == FW_IK_OK;
}

/* The touch-off that reaches `at` (the ball's centre at contact, as drawn) along the unit
 * direction d (into the surface), on the branch asked for or, where that cannot reach, the
 * next one that can. */
static int plan_one(const dhc_model *model, const fw_touch_config *cfg, const double at[3],
                    const double d[3], unsigned branch, fw_touch *t)
{
    double from[3];
    double to[3];
    double clear[3];
    along(at, -cfg->standoff_mm, d, from);
    along(at, cfg->overtravel_mm, d, to);
    along(at, -cfg->standoff_mm - cfg->clearance_mm, d, clear);
    memset(t, 0, sizeof *t);
    t->travel_mm = cfg->standoff_mm + cfg->overtravel_mm;
    for (unsigned k = 0U; k < 4U; ++k) {
        const unsigned b = (branch + k) % 4U;
        if (reach(model, from, b, 0, t->from_rad)) {
            memcpy(t->to_rad, t->from_rad, sizeof t->to_rad);
            memcpy(t->clear_rad, t->from_rad, sizeof t->clear_rad);
            if (reach(model, to, b, 1, t->to_rad) && reach(model, clear, b, 1, t->clear_rad)) {
                return 1;
            }
        }
    }
    return 0;
}

size_t fw_touch_plan(const dhc_model *model, const fw_touch_config *cfg, fw_touch *touches,
                     size_t cap)
{
    if (cfg->n_planes > FW_TOUCH_MAX_PLANES || cfg->n_gauges > FW_TOUCH_MAX_GAUGES ||
        cfg->per_plane > cap || cfg->per_gauge > cap) {
        return 0U; /* (and no product below wraps) */
    }
    const size_t want = cfg->n_planes * cfg->per_plane + 2U * cfg->n_gauges * cfg->per_gauge;
    if (want == 0U || want > cap || !(cfg->speed_mm_s > 0.0) || !(cfg->standoff_mm > 0.0) ||
        !(cfg->overtravel_mm > 0.0) || !(cfg->clearance_mm >= 0.0)) {
        return 0U;
    }
    size_t n = 0U;
    uint32_t index = cfg->seed % 1000U + 1U;
    for (size_t k = 0U; k < cfg->n_planes; ++k) {
        const fw_touch_plane *pl = &cfg->plane[k];
        const double into[3] = {-pl->normal[0], -pl->normal[1], -pl->normal[2]};
        for (size_t i = 0U, tries = 0U; i < cfg->per_plane; ++tries) {
            if (tries > 20U * cfg->per_plane) {
                return 0U; /* the region is out of the arm's reach */
            }
            double at[3];
            along(pl->point_mm, pl->half_mm[0] * halton(index, 2U), pl->u, at);
            along(at, pl->half_mm[1] * halton(index, 3U), pl->v, at);
            index++;
            if (plan_one(model, cfg, at, into, (unsigned)(i % 4U), &touches[n])) {
                touches[n].kind = (uint8_t)DHC_MEAS_PLANE;
                touches[n].target = (uint8_t)k;
                n++;
                i++;
            }
        }
    }
    for (size_t k = 0U; k < cfg->n_gauges; ++k) {
        const fw_touch_gauge *g = &cfg->gauge[k];
        const double minus[3] = {-g->axis[0], -g->axis[1], -g->axis[2]};
        for (size_t i = 0U, tries = 0U; i < cfg->per_gauge; ++tries) {
            if (tries > 20U * cfg->per_gauge) {
                return 0U;
            }
            double mid[3];
            double end_a[3];
            double end_b[3];
            along(g->centre_mm, g->half_mm * halton(index, 2U), g->lateral, mid);
            index++;
            along(mid, -0.5 * g->ends_mm, g->axis, end_a);
            along(mid, 0.5 * g->ends_mm, g->axis, end_b);
            /* end A is approached along +axis, end B along -axis; the two ends on different
             * branches where the arm has them, so a pair spans the arm's configurations */
            if (plan_one(model, cfg, end_a, g->axis, (unsigned)(i % 4U), &touches[n]) &&
                plan_one(model, cfg, end_b, minus, (unsigned)((i + 1U) % 4U), &touches[n + 1U])) {
                touches[n].kind = touches[n + 1U].kind = (uint8_t)DHC_MEAS_DISTANCE;
                touches[n].target = touches[n + 1U].target = (uint8_t)k;
                touches[n + 1U].second_end = 1U;
                n += 2U;
                i++;
            }
        }
    }
    return n;
}

static fw_fault probe_closed(fw_ctrl *c, int *closed)
{
    if (c->port->read_probe == NULL) {
        return FW_FAULT_ARGUMENT;
    }
    if (c->port->read_probe(c->port->ctx, closed) != FW_PORT_OK) {
        fw_ctrl_fault(c, FW_FAULT_PORT_IO, 0U);
        return c->fault;
    }
    return FW_FAULT_NONE;
}

/* A move straight to q in joint space, without the controller's approach from one side
 * (fw_ctrl_move_to's pre-pose, approach_rad back on every joint, could put the stylus a few
 * millimetres into the surface the approach pose stands off). */
static fw_fault move_direct(fw_ctrl *c, const double q[DHC_MAX_JOINTS])
{
    const double approach = c->cfg.approach_rad;
    c->cfg.approach_rad = 0.0;
    const fw_fault f = fw_ctrl_move_to(c, q, NULL);
    c->cfg.approach_rad = approach;
    return f;
}

fw_fault fw_touch_off(fw_ctrl *c, const fw_touch *t, double speed_mm_s,
                      double q_rad[DHC_MAX_JOINTS], int8_t dir[DHC_MAX_JOINTS])
{
    if (c->fault != FW_FAULT_NONE) {
        return c->fault;
    }
    if (c->port->read_probe == NULL || !(speed_mm_s > 0.0) || !(t->travel_mm > 0.0)) {
        return FW_FAULT_ARGUMENT;
    }
    /* from the clearance pose, straight down the surface's normal: a joint-space move between
     * two poses near a surface can dip into it on the way */
    if (move_direct(c, t->clear_rad) != FW_FAULT_NONE ||
        move_direct(c, t->from_rad) != FW_FAULT_NONE) {
        return c->fault;
    }
    int closed = 0;
    if (probe_closed(c, &closed) != FW_FAULT_NONE) {
        return c->fault;
    }
    if (closed) {
        fw_ctrl_fault(c, FW_FAULT_PROBE, 0U);
        return c->fault;
    }
    const double ticks_real = ceil(t->travel_mm / (speed_mm_s * c->cfg.tick_s));
    if (!(ticks_real >= 1.0 && ticks_real <= 1e7)) {
        return FW_FAULT_ARGUMENT; /* a creep of more than about three hours is no touch-off */
    }
    const uint32_t n_ticks = (uint32_t)ticks_real;
    const double ticks = (double)n_ticks;
    double q_ref[DHC_MAX_JOINTS];
    double qd_ref[DHC_MAX_JOINTS];
    for (size_t j = 0U; j < DHC_MAX_JOINTS; ++j) {
        qd_ref[j] = j < c->n ? (t->to_rad[j] - t->from_rad[j]) / (ticks * c->cfg.tick_s) : 0.0;
        dir[j] = qd_ref[j] < 0.0 ? (int8_t)-1 : (int8_t)1;
        q_ref[j] = t->from_rad[j];
    }
    for (uint32_t k = 1U; k <= n_ticks && !closed; ++k) {
        for (size_t j = 0U; j < c->n; ++j) {
            q_ref[j] = t->from_rad[j] + (t->to_rad[j] - t->from_rad[j]) * ((double)k / ticks);
        }
        if (fw_ctrl_tick(c, q_ref, qd_ref) != FW_FAULT_NONE ||
            probe_closed(c, &closed) != FW_FAULT_NONE) {
            return c->fault;
        }
    }
    if (!closed) {
        fw_ctrl_fault(c, FW_FAULT_PROBE, 0U);
        return c->fault;
    }
    memcpy(q_rad, c->q_rad, DHC_MAX_JOINTS * sizeof q_rad[0]); /* the tick that saw it */
    memcpy(c->dir, dir, sizeof c->dir);
    /* back off the way it came: straight back along the creep's line, then out to clearance */
    if (move_direct(c, t->from_rad) != FW_FAULT_NONE) {
        return c->fault;
    }
    return move_direct(c, t->clear_rad);
}

fw_fault fw_touch_acquire(fw_ctrl *c, const dhc_model *model, const fw_touch_config *cfg,
                          const fw_touch *touches, size_t n, dhc_sample *samples, size_t cap,
                          size_t *n_done)
{
    *n_done = 0U;
    for (size_t i = 0U; i < n; ++i) {
        const fw_touch *t = &touches[i];
        dhc_sample s;
        if (t->second_end) {
            return FW_FAULT_ARGUMENT; /* an end B without its end A before it */
        }
        if (*n_done >= cap) {
            return FW_FAULT_ARGUMENT;
        }
        memset(&s, 0, sizeof s);
        s.temp_c = model->thermal_ref_c;
        s.kind = t->kind;
        s.target = t->target;
        const fw_fault f = fw_touch_off(c, t, cfg->speed_mm_s, s.q_rad, s.dir);
        if (f != FW_FAULT_NONE) {
            return f; /* the controller's, or a refused touch-off's (no probe, a bad speed) */
        }
        if (t->kind == (uint8_t)DHC_MEAS_DISTANCE) {
            int8_t dir2[DHC_MAX_JOINTS];
            if (i + 1U >= n || !touches[i + 1U].second_end || touches[i + 1U].target != t->target) {
                return FW_FAULT_ARGUMENT;
            }
            const fw_fault f2 = fw_touch_off(c, &touches[i + 1U], cfg->speed_mm_s, s.q2_rad, dir2);
            if (f2 != FW_FAULT_NONE) {
                return f2;
            }
            s.distance_mm = cfg->gauge[t->target].ends_mm;
            ++i;
        }
        samples[*n_done] = s;
        ++*n_done;
    }
    return FW_FAULT_NONE;
}

#endif /* DHC_WITH_CONTACT */
