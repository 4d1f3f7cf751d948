/* dhcal_evidence.h - which missing effect the data support, and what is said of each
 * candidate: the one judgement `diagnose` and `refine` share (docs/effects.md 6-8).
 *
 * The score test (dhc_diagnose) screens the catalogue cheaply, but it takes the residual
 * for independent Gaussian noise; on a real arm the residual is mostly unmodelled
 * structure, so nearly every shape correlates with it. The screen's best candidates are
 * therefore refitted on the same rows (dhcal_fit_kept) and judged by what holds there:
 *   evidence      the cross-validated gain over the folds, against its standard error;
 *   size          what adding it changes at the tool, against the noise reference;
 *   plausibility  the joint deflection it applies over the joint ranges, against what real
 *                 arms show (DHCAL_PLAUSIBLE_*), and for compliance whether gravity loads
 *                 the axis at all in these poses;
 *   look-alikes   candidates whose fitted tool-error fields over these poses correlate
 *                 above DHCAL_LOOKALIKE_CORRELATION: these data cannot tell them apart.
 * Host code (heap allowed). */
#ifndef DHCAL_EVIDENCE_H
#define DHCAL_EVIDENCE_H

#include "dhcal_desk/dhcal_analysis.h"
#include "dhcal_desk/dhcal_cv.h"

/* Poses spread across the joint ranges (dhcal_workspace_poses). */
#define DHCAL_WORKSPACE_POSES 256U
/* Candidates of the screen refitted and cross-validated per judgement. */
#define DHCAL_EVIDENCE_TRIALS 6U
/* A candidate is added only when it lowers the cross-validated RMS by this share... */
#define DHCAL_EVIDENCE_MIN_GAIN 0.01
/* ... and its gain over the folds is positive at this one-sided level (t test of the fold
 * gains: their mean against their standard error). */
#define DHCAL_EVIDENCE_ALPHA 0.05
/* A candidate that raises the positioning uncertainty predicted over the model's joint
 * ranges by more than this factor is not named: fitted on a slice of its joint's turn it
 * can fit the rows and extrapolate by millimetres. */
#define DHCAL_EVIDENCE_MAX_UNCERTAINTY_GROWTH 1.25
/* Two candidates whose fitted tool-error fields correlate above this are look-alikes. */
#define DHCAL_LOOKALIKE_CORRELATION 0.9
/* The words for a look-alike (not its listing) change when its cross-validated RMS exceeds
 * the named one's by more than this factor: then the text says the cross-validation
 * prefers the named one clearly, and that the discriminating plan would confirm it. */
#define DHCAL_LOOKALIKE_CLEAR_MARGIN 1.2
#define DHCAL_MAX_LOOKALIKES 4U
/* Compliance about axis i is offered only when gravity's moment about it over the data's
 * poses (RMS, unit weight at frame j, the best j >= i) reaches this share of the arm's
 * reach: a vertical axis carries a moment only from the base's tilt (0.15-0.3 deg gives at
 * most 0.5 % of the reach), and a coefficient fitted to such a tiny regressor is some
 * other error wearing its name. */
#define DHCAL_COMPLIANCE_MIN_EXCITATION 0.02

/* What real arms show at most (docs/effects.md 8 gives the sources): a gear train's or an
 * encoder's ratio error; a once-to-four-per-turn joint error's amplitude (deg); half a
 * gear train's play (deg); the joint deflection gravity causes (deg). */
#define DHCAL_PLAUSIBLE_SCALE 0.015
#define DHCAL_PLAUSIBLE_HARMONIC_DEG 1.5
#define DHCAL_PLAUSIBLE_HARMONIC_HIGH_DEG 0.5 /* orders 2..4 */
#define DHCAL_PLAUSIBLE_BACKLASH_DEG 0.75     /* half of a 1.5 deg play */
#define DHCAL_PLAUSIBLE_COMPLIANCE_DEG 3.0

typedef enum {
    DHCAL_VERDICT_NAMED = 0,   /* passes every rule: the effect named */
    DHCAL_VERDICT_RUNNER_UP,   /* passes every rule; another one did better */
    DHCAL_VERDICT_LOOKALIKE,   /* passes; looks like the one named, which did better */
    DHCAL_VERDICT_SCREEN,      /* not significant in the score test's screen */
    DHCAL_VERDICT_NOT_TRIED,   /* significant, beyond the best DHCAL_EVIDENCE_TRIALS */
    DHCAL_VERDICT_NOT_EXCITED, /* compliance about an axis gravity barely loads here */
    DHCAL_VERDICT_FAILED,      /* its refit or cross-validation failed */
    DHCAL_VERDICT_GEOMETRY,    /* its refit moves the geometry out of its physical range */
    DHCAL_VERDICT_UNSUPPORTED, /* raises the uncertainty over the joint ranges too much */
    DHCAL_VERDICT_CV,          /* lowers the cross-validated RMS by less than the minimum */
    DHCAL_VERDICT_EVIDENCE,    /* its gain over the folds is not told from zero */
    DHCAL_VERDICT_SIZE,        /* changes the tool by less than the noise reference */
    DHCAL_VERDICT_UNPHYSICAL   /* fits only with a value real arms do not show */
} dhcal_verdict;

/* "named", "runner_up", "look_alike", "screen", "not_tried", "not_excited", "failed",
 * "geometry", "unsupported", "cv", "evidence", "size", "unphysical" (JSON `verdict`,
 * docs/cli.md). */
const char *dhcal_verdict_key(dhcal_verdict v);

/* The noise an effect must stand out of: the RMS 3-D error of one measured point that the
 * measurement and the arm's repeatability alone would leave. */
typedef struct {
    const char *source; /* "noise" (--noise), "repeats" (repeated poses), "repeatability"
                           (--repeatability or the model's repeatability_mm), or NULL */
    double point_mm;
} dhcal_size_reference;

/* The reference from, in order: the noise model (sqrt(3) meas_mm), repeated poses
 * (sqrt(3) times their per-coordinate scatter, dhcal_assess), the arm's repeatability RP
 * (ISO 9283: mean plus 3 sd of the distance from the barycentre; for isotropic normal
 * scatter RP is about 3.6 sd per coordinate and the point's RMS 1.7 sd, so RP / 2).
 * repeatability_mm <= 0: not known. */
dhcal_size_reference dhcal_size_reference_of(const dhcal_fit *fit, const dhcal_samples *s,
                                             double repeatability_mm);

typedef struct {
    dhcal_verdict verdict;
    int tried;            /* refitted and cross-validated */
    dhcal_cv cv;          /* when tried */
    double cv_gain;       /* 1 - cv / cv of the model without it */
    double gain_t;        /* fold gains' mean over its standard error */
    double gain_log10_p;  /* one-sided t test of that (F - 1 dof) */
    double gain_sure_mm2; /* the summed fold gains' lower one-sided bound at
                             DHCAL_EVIDENCE_ALPHA (mm^2): how much the folds agree it
                             gains at least; the one named has the largest */
    double tool_rms_mm;   /* what adding it changes at the tool over the data's poses */
    double tool_max_mm;
    double range_rms_mm; /* ... and over poses spread across the joint ranges */
    double range_max_mm;
    double workspace_std_mm; /* positioning uncertainty over the joint ranges with it */
    double magnitude;        /* the fitted effect's size: |s| for a scale; the amplitude
                                (deg) for a harmonic; half the play (deg) for backlash; for
                                compliance the largest deflection (deg) over the data's
                                poses and the joint ranges */
    double plausible_max;    /* what real arms show at most, same unit (0: no bound) */
    double excitation;       /* compliance: gravity moment RMS over the data / reach */
    size_t n_look_alikes;
    size_t look_alike[DHCAL_MAX_LOOKALIKES]; /* indices into the diagnosis' list */
    double look_alike_r[DHCAL_MAX_LOOKALIKES];
    char geometry_why[160]; /* DHCAL_VERDICT_GEOMETRY: the parameter out of range */
} dhcal_trial;

typedef struct {
    dhcal_trial trial[DHC_MAX_CANDIDATES]; /* per diagnosis candidate, in its order */
    dhcal_cv cv;                           /* the model without any */
    double workspace_std_mm;               /* the model without any */
    dhcal_size_reference reference;
    size_t named;         /* DHC_MAX_CANDIDATES: none */
    size_t best_rejected; /* the closest candidate that fell short (lowest CV RMS of those
                             tried, else the screen's best); DHC_MAX_CANDIDATES: none */
    size_t order[DHC_MAX_CANDIDATES]; /* candidates best first: the one named, the other
                                         tried ones by CV RMS, then the rest in the screen's
                                         order */
} dhcal_trials;

/* Judges the diagnosis of fit: the screen's significant candidates (compliance only where
 * gravity loads the axis), best first, DHCAL_EVIDENCE_TRIALS at most, are each added to the
 * fit's set and refitted from its solution on the same rows (s->flags as the fit left them;
 * no row is screened again), cross-validated on the same folds as cv (the fit's own
 * cross-validation, same rows), and measured at the tool; then every candidate gets its
 * verdict. A refit that moves the geometry out of its physical range from nominal
 * (dhcal_implausible) is no candidate. best_fit (may be NULL) receives the named one's
 * refit.
 * s->flags end as they started. DHCAL_IO_FAILED when memory runs out. */
int dhcal_judge_candidates(const dhc_model *nominal, const dhcal_fit *fit, const dhcal_cv *cv,
                           const dhc_diagnosis *diag, const dhcal_size_reference *reference,
                           dhcal_samples *s, const dhcal_samples *held, dhcal_trials *out,
                           dhcal_fit *best_fit, dhcal_error *err);

/* dhcal_trial.magnitude's bound for effect e (0: none). */
double dhcal_plausible_magnitude(dhc_effect e);

/* Gravity's moment about joint j's axis for a unit weight at frame k, RMS over the used
 * rows, as a share of the arm's reach: share[k] (k >= j; 0 elsewhere), how much the data
 * load the axis through each column. The candidate is offered when its best column reaches
 * DHCAL_COMPLIANCE_MIN_EXCITATION, and a column below it is not fitted (its weight sits on
 * or near the axis in every pose: a coefficient fitted to it is no stiffness). */
void dhcal_compliance_columns(const dhc_model *m, const dhcal_samples *s, size_t j,
                              double share[DHC_MAX_JOINTS]);

/* Poses across a model's joint ranges, in the caller's storage (about 52 KiB). */
typedef struct {
    dhcal_samples set;
    dhc_sample samples[DHCAL_WORKSPACE_POSES];
    uint8_t flags[DHCAL_WORKSPACE_POSES];
} dhcal_range_poses;

/* The poses across the model's joint ranges (DHCAL_WORKSPACE_POSES, deterministic), built in
 * *out: &out->set. */
const dhcal_samples *dhcal_workspace_poses(const dhc_model *model, dhcal_range_poses *out);

/* The evidence rule alone (JSON `significant`): refitted, cross-validated, its gain at
 * least DHCAL_EVIDENCE_MIN_GAIN and positive over the folds at DHCAL_EVIDENCE_ALPHA. */
int dhcal_trial_significant(const dhcal_trial *t);

/* The reason a candidate fell short, in words for people ("lowers the cross-validated RMS
 * by 0.4 % only"), into buf. */
void dhcal_verdict_words(const dhcal_trials *t, const dhc_diagnosis *diag, size_t c, char *buf,
                         size_t cap);

#endif /* DHCAL_EVIDENCE_H */
