/* dhcal_session.c - a session's model, options and rows (dhcal_session.h). */
#include "dhcal_desk/dhcal_session.h"

#include <string.h>

#include "dhcal_io/dhcal_model_map.h"

int dhcal_session_begin(dhcal_session *s, const dhcal_model *file, const char *path,
                        const char *noise, const char *geometry, const char *repeatability,
                        dhcal_error *err)
{
    memset(s, 0, sizeof *s);
    s->file = *file;
    s->repeatability_mm = file->repeatability_mm;
    int rc = dhcal_parse_noise(noise, &s->noise, err);
    if (rc == DHCAL_IO_OK && repeatability != NULL) {
        rc = dhcal_parse_repeatability(repeatability, &s->repeatability_mm, err);
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_parse_geometry(geometry, &s->geometry, err);
    }
    if (rc == DHCAL_IO_OK) {
        rc = dhcal_model_to_lib(&s->file, path, &s->model, err);
    }
    return rc;
}

int dhcal_session_build_rows(dhcal_session *s, const char *name, const char *held_name,
                             dhcal_error *err)
{
    int rc = dhcal_samples_build(&s->model, &s->data, name, &s->samples, err);
    if (rc == DHCAL_IO_OK && s->have_held) {
        rc = dhcal_samples_build(&s->model, &s->held_data, held_name, &s->held, err);
        if (rc == DHCAL_IO_OK) {
            rc = dhcal_samples_check_held(&s->samples, &s->held, held_name, err);
        }
    }
    return rc;
}

void dhcal_session_free(dhcal_session *s)
{
    dhcal_samples_free(&s->samples);
    dhcal_samples_free(&s->held);
    dhcal_dataset_free(&s->data);
    dhcal_dataset_free(&s->held_data);
}
