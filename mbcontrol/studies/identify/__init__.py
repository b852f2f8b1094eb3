"""Identification against measurements (the seed's section 4): fit a plant's unknown parameters
so that it reproduces measured regular-wave responses, with standard errors and validation on
runs the fit did not see.

Modules: `records` (measured records: CSV and netCDF readers, channel checks), `flume` (the
tank dataset of ../shared/data/tank as runs), `costs` (first harmonic, the seed's Eq. 67 peaks
and lows), `problem` (runs + plant + parameters -> residuals and their exact Jacobian), `fit`
(Nelder-Mead and Gauss-Newton, uncertainty), `extrapolation` (runs where the model was not
fitted), `report` (tables, JSON, figures).
"""
from .calibration import calibrate, calibrated_rows
from .crossval import cross_validate
from .crossval import table as crossval_table
from .extrapolation import ExtrapolationWarning
from .fit import FitResult, IdentifiabilityWarning, fit
from .problem import FitParameter, Identification, Run
from .flume import load_runs
from .intervals import coverage, prediction_intervals
from .records import Record, RecordError, read_csv, read_netcdf
from .report import (amplitude_rows, error_table, errors_block, parameter_table, plot_amplitudes,
                     plot_time_series, repeatability)
from .report import summary as identification_summary
from .setup import flume_identification, prediction

__all__ = ["Identification", "FitParameter", "Run", "fit", "FitResult", "IdentifiabilityWarning",
           "ExtrapolationWarning",
           "Record", "RecordError", "read_csv", "read_netcdf", "calibrate", "calibrated_rows",
           "cross_validate", "crossval_table", "load_runs", "coverage", "prediction_intervals",
           "amplitude_rows", "error_table", "errors_block", "parameter_table", "plot_amplitudes",
           "plot_time_series", "repeatability", "identification_summary",
           "flume_identification", "prediction"]
