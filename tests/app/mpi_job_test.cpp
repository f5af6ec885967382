// MPI jobs made of several modules (manifest attribute mpi-job): how modules are grouped into
// jobs and ranks, and what validation refuses.
#include "vrflow/app/mpi_job.hpp"

#include <gtest/gtest.h>

#include "test_support.hpp"
#include "vrflow/app/loader.hpp"
#include "vrflow/app/validate.hpp"
#include "vrflow/daemon/filter_registry.hpp"

namespace vrflow::app {
namespace {

// Package `par`: `block` forms jobs by its `job` parameter and may also start ranks of its own
// (`ranks`); `other` forms jobs too, `plain` does not.
const Catalog& jobCatalog() {
  static const Catalog catalog = [] {
    Catalog made = daemon::makeCatalog();
    const Status status = made.addPackageString(R"(<package name="par">
  <module type="block" executable="x" mpi-job="job" mpi-ranks="ranks">
    <output name="out"/>
    <param name="job" type="string"/>
    <param name="ranks" type="int" default="1" min="1"/>
  </module>
  <module type="other" executable="y" mpi-job="group">
    <param name="group" type="string" default="shared"/>
  </module>
  <module type="plain" executable="z">
    <param name="job" type="string"/>
  </module>
</package>
)",
                                                "par.xml");
    EXPECT_TRUE(status.ok()) << status.error().message;
    return made;
  }();
  return catalog;
}

Application load(std::string_view xml) {
  Result<Application> app = loadApplicationString(xml, "app.xml");
  EXPECT_TRUE(app.ok()) << app.error().message;
  return std::move(app).value();
}

std::vector<Diagnostic> check(std::string_view xml) {
  return checkApplicationString(xml, "app.xml", jobCatalog());
}

TEST(MpiJob, ModulesOfOneTypeWithTheSameValueAreOneJobRankedInModuleOrder) {
  const Application app = load(R"(<application>
  <modules>
    <module id="b0" package="par" type="block"><param name="job" value="water"/></module>
    <module id="alone" package="par" type="block"><param name="job" value="air"/></module>
    <module id="none" package="par" type="block"/>
    <module id="b1" package="par" type="block"><param name="job" value="water"/></module>
    <module id="o0" package="par" type="other"><param name="group" value="water"/></module>
    <module id="o1" package="par" type="other"/>
    <module id="p" package="par" type="plain"><param name="job" value="water"/></module>
    <module id="b2" package="par" type="block"><param name="job" value="water"/></module>
  </modules>
</application>
)");
  const std::vector<MpiJob> jobs = mpiJobs(app, jobCatalog());
  ASSERT_EQ(jobs.size(), 4u);
  EXPECT_EQ(jobs[0].name, "water");
  EXPECT_EQ(jobs[0].type, "block");
  EXPECT_EQ(jobs[0].modules, (std::vector<std::size_t>{0, 3, 7}));
  EXPECT_EQ(jobs[0].moduleIds(app), "b0, b1, b2");
  EXPECT_EQ(jobs[1].name, "air");
  EXPECT_EQ(jobs[1].modules, (std::vector<std::size_t>{1}));
  // Same value, another type: another job. An unset parameter takes the manifest's default.
  EXPECT_EQ(jobs[2].name, "water");
  EXPECT_EQ(jobs[2].type, "other");
  EXPECT_EQ(jobs[2].modules, (std::vector<std::size_t>{4}));
  EXPECT_EQ(jobs[3].name, "shared");
  EXPECT_EQ(jobs[3].modules, (std::vector<std::size_t>{5}));
  const std::vector<Diagnostic> found = check(R"(<application>
  <modules>
    <module id="b0" package="par" type="block"><param name="job" value="water"/></module>
    <module id="b1" package="par" type="block"><param name="job" value="water"/></module>
  </modules>
</application>
)");
  EXPECT_TRUE(found.empty()) << formatDiagnostics(found);
}

TEST(MpiJob, AJobOnTwoHostsIsAnErrorAtTheModuleOnTheOtherHost) {
  const std::vector<Diagnostic> found = check(R"(<application>
  <hosts>
    <host id="a"/>
    <host id="b" address="127.0.0.2"/>
  </hosts>
  <modules>
    <module id="b0" package="par" type="block"><param name="job" value="water"/></module>
    <module id="b1" package="par" type="block" host="b"><param name="job" value="water"/></module>
    <module id="b2" package="par" type="block" host="a"><param name="job" value="water"/></module>
    <module id="b3" package="par" type="block" host="b"><param name="job" value="water"/></module>
    <module id="c0" package="par" type="block" host="b"><param name="job" value="air"/></module>
  </modules>
</application>
)");
  EXPECT_ONLY_ERROR_AT(
      found, 8, 48,
      "module 'b1' is on host 'b' but MPI job 'water' (par/block) began on host 'a' "
      "(b0, b2 on host 'a'; b1, b3 on host 'b'): the modules of one MPI job "
      "must be on one host (MPI jobs across hosts are not supported yet)");
}

TEST(MpiJob, AModuleOfAJobCannotAlsoStartRanksOfItsOwn) {
  const std::vector<Diagnostic> found = check(R"(<application>
  <modules>
    <module id="b0" package="par" type="block">
      <param name="job" value="water"/>
      <param name="ranks" value="4"/>
    </module>
    <module id="solo" package="par" type="block"><param name="ranks" value="4"/></module>
    <module id="one" package="par" type="block">
      <param name="job" value="air"/>
      <param name="ranks" value="1"/>
    </module>
  </modules>
</application>
)");
  EXPECT_ONLY_ERROR_AT(found, 5, 27,
                       "module 'b0' runs as one rank of MPI job 'water' (its 'job' parameter), so "
                       "its 'ranks' parameter must be 1, got 4 (a module of an MPI job cannot "
                       "start ranks of its own)");
}

}  // namespace
}  // namespace vrflow::app
