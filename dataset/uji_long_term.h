// Reader for the long-term UJI library Wi-Fi data set (G. M. Mendoza-Silva, P. Richter,
// J. Torres-Sospedra, E. S. Lohan and J. Huerta, "Long-term WiFi fingerprinting dataset for
// research on robust indoor positioning", Data 3(1), 2018): fingerprints taken at the same places
// of two library floors (3 and 5) month after month, in one folder per month (db/01, db/02, ...)
// holding a training set (trn01; month 01 holds more) and test sets (tst01 ... tst05). A set is
// four header-less CSV files side by side, one row per fingerprint, rows aligned across files:
//
//   <set>rss.csv  one column per access point, the same access points in the same order in every
//                 file of the data set; RSSI in dBm, 100 = not detected. Column k (1-based) is
//                 named "AP001", "AP002", ... so that sets of different months share AP names.
//   <set>crd.csv  x and y (metres) and the floor.                                  (required)
//   <set>tms.csv  the time of the row: seconds (a number), a MATLAB date number (a number between
//                 719529 and 767011, i.e. the years 1970 to 2100, in days), 17 digits
//                 yyyymmddHHMMSSfff as the published files hold them (e.g. 20160602155217232;
//                 local time, read as if UTC: every row of a set shifts alike), or 14 digits
//                 without the milliseconds, six numbers (year, month, day, hour, minute, second)
//                 or text "YYYY-MM-DD HH:MM:SS" (UTC); years 1970 to 2100.
//                 (optional; without it the row number is the time)
//   <set>ids.csv  whole numbers; the first is kept as the row's identifier.          (optional)
//
// Any of the four files is named to reach the others: `IsUjiLongTermSet("db/01/trn01rss.csv")`.
#ifndef RATSLAM_DATASET_UJI_LONG_TERM_H_
#define RATSLAM_DATASET_UJI_LONG_TERM_H_

#include <string>
#include <vector>

#include "common/status.h"
#include "dataset/ujiindoorloc.h"

namespace ratslam::dataset {

struct UjiLongTermFiles {
  std::string rss, crd, tms, ids;  // tms and ids empty when absent
};

struct UjiLongTermReport {
  size_t rows = 0;
  size_t skipped_malformed = 0;  // lenient mode only
  size_t access_points = 0;      // columns of the rss file
  bool has_times = false, has_ids = false;
};

// The files of the set that `path` (any of its four files) belongs to, or an error naming what is
// missing. The rss and crd files must exist.
StatusOr<UjiLongTermFiles> FindUjiLongTermFiles(const std::string& path);

// True when `path` is a file named <set>rss.csv (or crd, tms, ids) with <set>rss.csv and
// <set>crd.csv beside it: a long-term set rather than a UJIIndoorLoc file.
bool IsUjiLongTermSet(const std::string& path);

// The set's rows as labelled scans (floor from crd; the row's identifier in `space`; user and
// phone 0). Errors name the file, line and field; the files must have the same number of rows.
// `lenient` skips (and counts) rows with a malformed field in any of the files.
StatusOr<std::vector<LabelledScan>> ReadUjiLongTermSet(const std::string& path,
                                                       bool lenient = false,
                                                       UjiLongTermReport* report = nullptr);

}  // namespace ratslam::dataset

#endif  // RATSLAM_DATASET_UJI_LONG_TERM_H_
