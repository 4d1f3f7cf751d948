/* fit_files.c - the C program of docs/library.md, "The file layer": a model file and a
 * measurement CSV loaded with dhcal::io, the model fitted with dhcal::dhcal, the result
 * printed. Usage: fit_files MODEL.json DATA.csv. Exit 0 when the fit converged, 1 when it did
 * not, 2 for a file it could not read (the reason, with file and line, on stderr). */
#include <stdio.h>

#include <dhcal/dhcal.h>
#include <dhcal_io/dhcal_io.h>
#include <dhcal_io/dhcal_data.h>

int main(int argc, char **argv)
{
    if (argc != 3) {
        fprintf(stderr, "usage: fit_files MODEL.json DATA.csv\n");
        return 2;
    }
    static dhcal_model file; /* the model file as written (names, limits) */
    static dhc_model model;  /* ... as the library computes with it */
    dhcal_dataset data = {0};
    dhcal_samples samples = {0};
    dhcal_error err = {0};
    if (dhcal_model_load(argv[1], &file, &err) != DHCAL_IO_OK ||
        dhcal_model_to_lib(&file, argv[1], &model, &err) != DHCAL_IO_OK ||
        dhcal_csv_load(argv[2], model.arm.n_joints, &data, &err) != DHCAL_IO_OK ||
        dhcal_samples_build(&model, &data, argv[2], &samples, &err) != DHCAL_IO_OK) {
        fprintf(stderr, "fit_files: %s\n", err.msg);
        dhcal_dataset_free(&data);
        return 2;
    }
    /* joint offsets and link geometry, as the paper fits them */
    dhc_param_set set;
    dhc_calib_options opt;
    static dhc_calib_workspace ws; /* large: off the stack */
    static dhc_calib_report rep;
    dhc_calib_default_options(&opt);
    dhc_status st = dhc_params_base_model(&set, &model);
    if (st == DHC_OK) {
        st = dhc_calib_fit(&model, &set, dhcal_samples_read, &samples, samples.n, samples.flags,
                           &opt, &ws, &rep);
    }
    printf("%s: %zu rows, %zu parameters (%zu identifiable): RMS %.4f mm, %s\n", argv[2], samples.n,
           set.count, rep.rank, rep.rms_mm, dhc_status_str(st));
    dhcal_samples_free(&samples);
    dhcal_dataset_free(&data);
    return st == DHC_OK ? 0 : 1;
}
