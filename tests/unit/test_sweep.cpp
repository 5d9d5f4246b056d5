// The pure parts of `millsim sweep`: reading --vary, writing values without float noise, the
// order of the points, their directory names, and the sweep.csv text.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <omp.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "millsim/core/error.hpp"
#include "millsim/sim/sweep.hpp"

namespace millsim {
namespace {

using Values = std::vector<std::string>;

/// The message of the InputError that parse_vary(argument) throws ("" if none).
std::string refusal(const std::string& argument) {
  try {
    parse_vary(argument);
  } catch (const InputError& error) {
    return error.what();
  }
  return {};
}

TEST(Sweep, ARangeRunsFromStartToStopInclusive) {
  const SweepAxis axis = parse_vary("mill.speed=0.3:0.9:0.1");
  EXPECT_EQ(axis.key, "mill.speed");
  // 0.3 + 6 × 0.1 is 0.9000000000000001 and (0.9 − 0.3) / 0.1 is 5.999999999999999: the stop
  // is included within the rounding tolerance and each value is printed as typed.
  EXPECT_EQ(axis.values, (Values{"0.3", "0.4", "0.5", "0.6", "0.7", "0.8", "0.9"}));
}

TEST(Sweep, ARangeStopsAtTheLastWholeStepBeforeStop) {
  EXPECT_EQ(parse_vary("mill.speed=0.3:0.95:0.2").values, (Values{"0.3", "0.5", "0.7", "0.9"}));
  EXPECT_EQ(parse_vary("mill.lifters.count=4:16:4").values, (Values{"4", "8", "12", "16"}));
  EXPECT_EQ(parse_vary("mill.speed=0.5:0.5:0.1").values, (Values{"0.5"}));
}

TEST(Sweep, ARangeMayCountDownAndUseExponents) {
  EXPECT_EQ(parse_vary("mill.speed=0.9:0.6:-0.1").values, (Values{"0.9", "0.8", "0.7", "0.6"}));
  EXPECT_EQ(parse_vary("simulation.time_step=1e-5:3e-5:1e-5").values,
            (Values{"1e-05", "2e-05", "3e-05"}));
}

TEST(Sweep, AListKeepsItsValuesAsWritten) {
  const SweepAxis axis = parse_vary(" charge.filling = 0.2, 0.30 ,0.4");
  EXPECT_EQ(axis.key, "charge.filling");
  EXPECT_EQ(axis.values, (Values{"0.2", "0.30", "0.4"}));
  EXPECT_EQ(parse_vary("simulation.time_step=\"auto\",1e-5").values, (Values{"\"auto\"", "1e-5"}));
  EXPECT_EQ(parse_vary("mill.speed=0.5").values, (Values{"0.5"}));
}

TEST(Sweep, AListSplitsOnlyBetweenValues) {
  // Commas and colons inside a TOML string, array or inline table belong to the value.
  EXPECT_EQ(parse_vary("charge.sizes=[{diameter = 0.1, mass_fraction = 1}],"
                       "[{diameter = 0.08, mass_fraction = 0.5}, {diameter = 0.05, "
                       "mass_fraction = 0.5}]")
                .values,
            (Values{"[{diameter = 0.1, mass_fraction = 1}]",
                    "[{diameter = 0.08, mass_fraction = 0.5}, {diameter = 0.05, mass_fraction = "
                    "0.5}]"}));
  EXPECT_EQ(parse_vary("reference.case=\"a,b:c\", 'd,e', \"f\\\",g\"").values,
            (Values{"\"a,b:c\"", "'d,e'", "\"f\\\",g\""}));
  // Also where the string with the colon is not the first value (it was taken for a range).
  EXPECT_EQ(parse_vary("reference.case=\"a\",\"b:c\", ['d:e']").values,
            (Values{"\"a\"", "\"b:c\"", "['d:e']"}));
  // Multi-line strings hold single quotes; a bracket inside a string in an array is text.
  EXPECT_EQ(parse_vary(R"(reference.case="""a"b,c""",'''a'b,c''',["a]", 1],2)").values,
            (Values{R"("""a"b,c""")", "'''a'b,c'''", R"(["a]", 1])", "2"}));
  // A quote or bracket inside plain text opens nothing (TOML's open only a value).
  EXPECT_EQ(parse_vary("reference.case=it's,b, a[1 ,c").values, (Values{"it's", "b", "a[1", "c"}));
  // An unclosed string or bracket at the start of a value keeps the rest whole; the TOML
  // reader refuses it later where its key takes a number.
  EXPECT_EQ(parse_vary("charge.sizes=[0.1, 0.2").values, (Values{"[0.1, 0.2"}));
  EXPECT_EQ(parse_vary("reference.case=\"a, b").values, (Values{"\"a, b"}));
  // A colon outside them still makes a range.
  EXPECT_EQ(parse_vary("mill.speed=0.5:0.7:0.1").values, (Values{"0.5", "0.6", "0.7"}));
}

TEST(Sweep, RefusesABadSpecNamingTheArgumentAndWhatIsAllowed) {
  // Each bad argument with the reason it alone has: the message is "command line (--vary
  // ARGUMENT): REASON; allowed: KEY=START:STOP:STEP ..." with the reason right after the name,
  // so a refusal for the wrong reason fails.
  struct Case {
    std::string argument;
    std::string reason;
  };
  const std::vector<Case> cases{
      {"mill.speed", "no '=' between the key and the values"},
      {"mill.speed=0.3:0.9", "\"0.3:0.9\" has 2 parts separated by ':', not 3"},
      {"mill.speed=0.3:0.9:0.1:2", "\"0.3:0.9:0.1:2\" has 4 parts separated by ':', not 3"},
      {"mill.speed=a:0.9:0.1", "START \"a\" is not a number"},
      {"mill.speed=0.3:0.9:0", "STEP is 0"},
      {"mill.speed=0.9:0.3:0.1", "STEP 0.1 leads away from STOP 0.3"},
      {"mill.speed=0.3,,0.5", "value 2 of the list is empty"},
      {"mill.speed=", "value 1 of the list is empty"},
      {"mill.speed=0.3:inf:0.1", "STOP \"inf\" is not a number"},
  };
  for (const Case& c : cases) {
    const std::string message = refusal(c.argument);
    // (The argument without '=' is named whole: "--vary mill.speed".)
    const std::string expected =
        "command line (--vary " + c.argument + "): " + c.reason + "; allowed: KEY=START:STOP:STEP";
    EXPECT_TRUE(message.starts_with(expected))
        << "expected: " << expected << "\n  got: " << message;
  }
}

TEST(Sweep, RefusesABadKeyTooManyPointsAndOutputDirectory) {
  EXPECT_NE(refusal("mill..speed=0.3").find("is not a key"), std::string::npos);
  EXPECT_NE(refusal("=0.3").find("is not a key"), std::string::npos);
  EXPECT_NE(refusal("mill speed=0.3").find("is not a key"), std::string::npos);
  EXPECT_NE(refusal("output.directory=a,b").find("--out"), std::string::npos);
  EXPECT_NE(refusal("mill.speed=0:1:1e-6").find("at most 10000 values"), std::string::npos);
  EXPECT_THROW(check_sweep_axes({{"mill.speed", {"0.5"}}, {"mill.speed", {"0.6"}}}), InputError);
  const SweepAxis hundred = parse_vary("mill.speed=1:100:1");
  EXPECT_NO_THROW(check_sweep_axes({hundred, {"charge.filling", Values(100, "0.3")}}));
  EXPECT_THROW(check_sweep_axes({hundred, {"charge.filling", Values(101, "0.3")}}), InputError);
}

TEST(Sweep, NumbersAreWrittenWithoutFloatNoise) {
  EXPECT_EQ(decimal_places("0.25"), 2);
  EXPECT_EQ(decimal_places("3"), 0);
  EXPECT_EQ(decimal_places("2.5e-4"), 5);
  EXPECT_EQ(decimal_places("1e3"), 0);
  EXPECT_EQ(decimal_places("-0.125E+1"), 2);
  EXPECT_EQ(decimal_text(0.3 + 4 * 0.1, 1), "0.7");
  EXPECT_EQ(decimal_text(0.1 + 0.2, 2), "0.3");
  EXPECT_EQ(decimal_text(2.0, 1), "2");
  // Steps too small for 30 places: rounded to significant digits, not to "0".
  EXPECT_EQ(decimal_places("1e-40"), 40);
  EXPECT_EQ(decimal_text(1e-40 + 2 * 1e-40, 40), "3e-40");
  EXPECT_EQ(decimal_text(0.3e-35 + 6 * 0.1e-35, 36), "9e-36");
  EXPECT_EQ(parse_vary("charge.porosity=0:2e-40:1e-40").values,
            (std::vector<std::string>{"0", "1e-40", "2e-40"}));
  EXPECT_EQ(parse_vary("mill.speed=1e-320:2e-320:1e-320").values,
            (std::vector<std::string>{"1e-320", "2e-320"}));
  EXPECT_EQ(decimal_text(-1e-17, 1), "0");
  EXPECT_EQ(decimal_text(0.125, 3), "0.125");
}

TEST(Sweep, TheFirstAxisVariesSlowest) {
  const std::vector<SweepAxis> axes{{"a", {"1", "2"}}, {"b", {"x", "y", "z"}}};
  const std::vector<Values> points = cartesian_product(axes);
  EXPECT_EQ(points, (std::vector<Values>{
                        {"1", "x"}, {"1", "y"}, {"1", "z"}, {"2", "x"}, {"2", "y"}, {"2", "z"}}));
  EXPECT_EQ(point_overrides(axes, points[4]), (Values{"a=2", "b=y"}));
  EXPECT_EQ(cartesian_product({}), (std::vector<Values>{{}}));
}

TEST(Sweep, DirectoryNamesAreIndexedReadableAndFilesystemSafe) {
  const std::vector<SweepAxis> axes{{"mill.speed", {}}, {"simulation.time_step", {}}};
  EXPECT_EQ(point_directory_name(7, 20, axes, {"0.7", "1e-5"}),
            "007_mill.speed=0.7_simulation.time_step=1e-5");
  EXPECT_EQ(point_directory_name(3, 20, axes, {"0.7", "\"a/b c\""}),
            "003_mill.speed=0.7_simulation.time_step=_a_b_c_");
  EXPECT_EQ(point_directory_name(42, 1500, axes, {"1", "2"}),
            "0042_mill.speed=1_simulation.time_step=2");
}

TEST(Sweep, CsvHasOneRowPerPointAndEveryScalar) {
  const std::vector<SweepAxis> axes{{"mill.speed", {"0.5", "0.7", "0.9"}}};
  const std::vector<SweepRow> rows{
      {{"0.5"},
       "ok",
       {{"power_kw", 0.25}, {"empirical.bond_kw", 1.5}},
       "000_mill.speed=0.5",
       {"a warning", "another, with a comma"}},
      {{"0.7"}, "failed: could not place 3 discs, \"try\" less", {}, "001_mill.speed=0.7", {}},
      {{"0.9"}, "pending", {}, "002_mill.speed=0.9", {}},
  };
  EXPECT_EQ(sweep_csv(axes, rows),
            "point,directory,mill.speed,status,warnings,power_kw,empirical.bond_kw\n"
            "0,000_mill.speed=0.5,0.5,ok,\"a warning; another, with a comma\",0.25,1.5\n"
            "1,001_mill.speed=0.7,0.7,\"failed: could not place 3 discs, \"\"try\"\" less\",,,\n"
            "2,002_mill.speed=0.9,0.9,pending,,,\n");
}

TEST(Sweep, CsvColumnsKeepTheSummarysOrderWhicheverRowsHaveThem) {
  // b is missing from the first row (a toe angle a centrifuging charge lacks, say): it still
  // comes between a and c, as in the rows that have it, in whichever order the rows come.
  const std::vector<SweepAxis> axes{{"k", {"1", "2"}}};
  const std::vector<SweepRow> without_first{
      {{"1"}, "ok", {{"a", 1.0}, {"c", 3.0}}, "", {}},
      {{"2"}, "ok", {{"a", 2.0}, {"b", 0.1}, {"c", 4.0}}, "", {}}};
  const std::vector<SweepRow> with_first{
      {{"2"}, "ok", {{"a", 2.0}, {"b", 0.1}, {"c", 4.0}}, "", {}},
      {{"1"}, "ok", {{"a", 1.0}, {"c", 3.0}}, "", {}}};
  EXPECT_EQ(sweep_csv(axes, without_first),
            "point,directory,k,status,warnings,a,b,c\n0,,1,ok,,1,,3\n1,,2,ok,,2,0.1,4\n");
  EXPECT_EQ(sweep_csv(axes, with_first),
            "point,directory,k,status,warnings,a,b,c\n0,,2,ok,,2,0.1,4\n1,,1,ok,,1,,3\n");
  // A name the first row lacks at its start, and one at its end.
  const std::vector<SweepRow> ends{{{"1"}, "ok", {{"b", 1.0}}, "", {}},
                                   {{"2"}, "ok", {{"a", 2.0}, {"b", 3.0}, {"c", 4.0}}, "", {}}};
  EXPECT_TRUE(sweep_csv(axes, ends).starts_with("point,directory,k,status,warnings,a,b,c\n"));
}

TEST(Sweep, CsvRowsReadBackWhatCsvLineWrites) {
  const std::vector<std::string> cells{"plain", "a, b", "say \"hi\"", "two\nlines", ""};
  const std::string text = csv_line(cells) + "x,y\r\nlast";
  const std::vector<std::vector<std::string>> rows = csv_rows(text);
  ASSERT_EQ(rows.size(), 3U);
  EXPECT_EQ(rows[0], cells);
  EXPECT_EQ(rows[1], (std::vector<std::string>{"x", "y"}));
  EXPECT_EQ(rows[2], (std::vector<std::string>{"last"}));
  EXPECT_TRUE(csv_rows("").empty());
}

TEST(Sweep, ALongValueIsCutInTheDirectoryNameAndHashed) {
  const std::vector<SweepAxis> axes{{"charge.sizes", {}}};
  const std::string sizes_a =
      "[{diameter = 0.1, mass_fraction = 0.2}, {diameter = 0.08, mass_fraction = 0.2}, "
      "{diameter = 0.06, mass_fraction = 0.2}, {diameter = 0.05, mass_fraction = 0.2}, "
      "{diameter = 0.04, mass_fraction = 0.2}]";
  std::string sizes_b = sizes_a;
  sizes_b[sizes_b.size() - 3] = '1';  // the last fraction, beyond the cut
  const std::string a = point_directory_name(0, 2, axes, {sizes_a});
  const std::string b = point_directory_name(0, 2, axes, {sizes_b});
  EXPECT_EQ(a.size(), 3 + longest_point_values);
  EXPECT_EQ(a.substr(0, 40), "000_charge.sizes=__diameter_=_0.1__mass_");
  EXPECT_NE(a, b) << "the hash tells values apart that the cut does not";
  EXPECT_EQ(a.substr(0, a.size() - 8), b.substr(0, b.size() - 8));
  EXPECT_EQ(a, point_directory_name(0, 2, axes, {sizes_a})) << "the same name every time";
}

TEST(Sweep, TooManyValuesAreCountedExactly) {
  try {
    (void)parse_vary("mill.speed=0:1:0.0001");
    ADD_FAILURE() << "10 001 values taken";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(": 10001 values; allowed: at most 10000 values"),
              std::string::npos)
        << e.what();
  }
}

TEST(Sweep, TableShowsPowersAndStatus) {
  const std::vector<SweepAxis> axes{{"mill.speed", {"0.5", "0.7"}}};
  const std::vector<SweepRow> rows{
      {{"0.5"},
       "ok",
       {{"power_kw", 0.25}, {"power_dissipation_kw", 0.26}, {"energy_balance_error", 0.001}},
       "",
       {}},
      {{"0.7"}, "failed: boom", {}, "", {}},
  };
  const std::string table = sweep_table(axes, rows);
  for (const char* part : {"mill.speed", "power_kw", "power_dissipation_kw", "energy_balance_error",
                           "status", "0.25", "0.26", "0.001", "ok\n", "failed: boom\n"}) {
    EXPECT_NE(table.find(part), std::string::npos) << part << " not in\n" << table;
  }
}

}  // namespace
}  // namespace millsim

TEST(Sweep, PointsShareTheThreads) {
  const auto expect_share = [](int threads, std::size_t points, int at_a_time, int each,
                               const std::string& text) {
    SCOPED_TRACE(fmt::format("{} threads, {} points", threads, points));
    const millsim::ThreadShare share = millsim::share_threads(threads, points);
    EXPECT_EQ(share.at_a_time, at_a_time);
    EXPECT_EQ(share.threads_each, each);
    EXPECT_EQ(millsim::describe(share), text);
  };
  expect_share(1, 5, 1, 1, "one at a time");
  expect_share(2, 1, 1, 2, "one at a time");
  expect_share(8, 1, 1, 8, "one at a time");
  expect_share(2, 2, 2, 1, "2 at a time");
  expect_share(2, 7, 2, 1, "2 at a time");
  expect_share(8, 3, 3, 2, "3 at a time, 2 threads each");
  expect_share(8, 2, 2, 4, "2 at a time, 4 threads each");
  expect_share(4, 5, 4, 1, "4 at a time");
}

TEST(Sweep, SharedJobsRunEachIndexOnceOnTheirShareOfThreads) {
  for (const millsim::ThreadShare share :
       {millsim::ThreadShare{1, 2}, millsim::ThreadShare{3, 1}, millsim::ThreadShare{2, 2}}) {
    SCOPED_TRACE(millsim::describe(share));
    constexpr std::size_t count = 40;
    std::vector<std::atomic<int>> runs(count);
    std::vector<int> threads(count, 0);
    std::mutex seen;
    std::set<std::thread::id> callers;
    millsim::run_shared(count, share, [&](std::size_t i) {
      ++runs[i];
      threads[i] = omp_get_max_threads();  // what the job's parallel regions would get
      const std::lock_guard lock(seen);
      callers.insert(std::this_thread::get_id());
    });
    for (std::size_t i = 0; i < count; ++i) {
      EXPECT_EQ(runs[i].load(), 1) << i;
      // One at a time the jobs run on this thread, with its own setting.
      EXPECT_EQ(threads[i], share.at_a_time > 1 ? share.threads_each : omp_get_max_threads()) << i;
    }
    EXPECT_LE(callers.size(), static_cast<std::size_t>(share.at_a_time));
    if (share.at_a_time == 1) {
      EXPECT_TRUE(callers.contains(std::this_thread::get_id()));
    }
  }
}

TEST(Sweep, SharedJobsStopStartingAfterOneThrowsAndRethrowIt) {
  for (const int at_a_time : {1, 2}) {
    SCOPED_TRACE(at_a_time);
    std::atomic<int> started{0};
    try {
      millsim::run_shared(1000, millsim::ThreadShare{at_a_time, 1}, [&](std::size_t i) {
        ++started;
        if (i == 3) throw std::runtime_error("job 3 failed");
        // Jobs that take a while, as a point's run does: the others cannot race through the
        // list while job 3's exception is on its way.
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      });
      ADD_FAILURE() << "no exception";
    } catch (const std::runtime_error& error) {
      EXPECT_STREQ(error.what(), "job 3 failed");
    }
    // Jobs 0 to 3 and the few the other thread took meanwhile (one or two, unless this
    // thread stalls), not the rest.
    EXPECT_GE(started.load(), 4);
    EXPECT_LE(started.load(), at_a_time == 1 ? 4 : 100);
  }
}
