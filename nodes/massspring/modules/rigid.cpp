// massspring/rigid: the rigid / mass-spring interactor. Nodes of every net against every rigid
// shape (signed distance in the body frame); node forces to the nets, and to each touched rigid
// one ForceEvent with the opposite total force at its centre of mass and the torque about it.
// Nodes against every captured user (type `user`) too, unless `user-contacts` is false (where the
// net's animator collides with the users inside its sub-steps): node forces only, the user is
// immovable.
#include <cstdio>

#include "common.hpp"
#include "vrflow/camera/capture_stamps.hpp"
#include "vrflow/massspring/contact.hpp"
#include "vrflow/massspring/objects.hpp"

int main() {
  using namespace vrflow;
  using namespace vrflow::massspring;
  UserContactMemory userMemory;
  return modules::runContactInteractor(
      "vrflow-massspring-rigid",
      [&userMemory](Module& module, const SceneCopy& scene, const ContactParams& contact,
                    ContactMemory* memory) {
        auto result = rigidContacts(scene.nets(), scene.rigids(), contact, memory);
        const auto users = scene.users();
        if (!users.empty() && module.params().getBool("user-contacts"))
          addUserContacts(scene.nets(), users, contact, result, &userMemory);
        auto out =
            modules::nodeForcesMessage(module, result.nodeForces, result.rigidForces.size() * 128);
        for (const auto& [id, force] : result.rigidForces) out.builder().addForce(id, force);
        // Which camera frame the users came from (nodes/camera, latency in frames).
        if (const auto frame = scene.userCaptureIteration())
          out.builder().addInt64Stamp(camera::kUsedCaptureIterationStamp, *frame);
        return out;
      },
      /*withGravity=*/true);
}
