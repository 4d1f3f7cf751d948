/* dhc_param_kind.h - the kinds of quantity a fit adjusts (dhc_params.h's parameter ids,
 * and the effects of the catalogue, dhc_effects.h, that group them): below both, so that
 * neither includes the other to name them. */
#ifndef DHC_PARAM_KIND_H
#define DHC_PARAM_KIND_H

#ifdef __cplusplus
extern "C" {
#endif

typedef enum {
    DHC_P_THETA = 0, /* joint offset theta_offset_i, rad */
    DHC_P_D,         /* d_i, mm */
    DHC_P_A,         /* a_i, mm */
    DHC_P_ALPHA,     /* alpha_i, rad */
    DHC_P_BETA,      /* Hayati beta_i, rad */
    DHC_P_BASE_X,    /* base origin in the world, mm */
    DHC_P_BASE_Y,
    DHC_P_BASE_Z,
    DHC_P_BASE_RX, /* small rotation of the base about world x/y/z through its origin, rad */
    DHC_P_BASE_RY,
    DHC_P_BASE_RZ,
    DHC_P_TOOL_X, /* tool point in the last link frame, mm */
    DHC_P_TOOL_Y,
    DHC_P_TOOL_Z,
    DHC_P_JOINT_SCALE,  /* s_i (joint) */
    DHC_P_HARMONIC_SIN, /* A_ik, rad (joint i, aux k - 1: order k = 1..4) */
    DHC_P_HARMONIC_COS, /* B_ik, rad (joint i, aux k - 1) */
    DHC_P_BACKLASH,     /* b_i, rad (joint) */
    DHC_P_COMPLIANCE,   /* c_ij, rad/mm (joint i, aux j >= i) */
    DHC_P_MEAS_SCALE,   /* s_m */
    DHC_P_MEAS_OFFSET,  /* o_k, mm (aux k = 0..2) */
    DHC_P_MEAS_ANCHOR,  /* anchor coordinate, mm (aux = 3 k + axis) */
    DHC_P_THERMAL,      /* k, 1/K */
    DHC_P_DRIFT_SCALE,  /* k_d, 1/s */
    DHC_P_DRIFT_OFFSET, /* v, mm/s (aux = world axis 0..2) */
    DHC_P_PLANE_TILT,   /* small turn of plane `joint`'s normal toward its tangent aux (0, 1:
                           dhc_plane_tangents), rad */
    DHC_P_PLANE_OFFSET, /* plane `joint`'s offset h, mm */
    DHC_P_POINT,        /* fixed point `joint`'s coordinate aux (world axis 0..2), mm */
    DHC_P_KIND_COUNT
} dhc_param_kind;

#ifdef __cplusplus
}
#endif

#endif /* DHC_PARAM_KIND_H */
