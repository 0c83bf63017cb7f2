#include "rascal_sim/World.hpp"

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <deque>
#include <mutex>
#include <stdexcept>

#include "rascal_sim/MunsellTable.hpp"
#include "rascal_sim/SherdMeshBuilder.hpp"

namespace rascal_sim {

namespace {
using rascal_workcell::Workcell;

constexpr double kGravity = 9.81;
constexpr double kPlatformMass = 0.30;  // [kg] the weighing pan (tared away)

/// The weighing platform, the simulator's own body: the scale station's area, the workcell's
/// platform thickness, its top at the station's surface_z. A scale standing lower than that
/// thickness has the rest of its platform below the table top, where nothing collides with it.
struct PlatformBox {
  Eigen::Vector3d centre, size;
  double yaw;
};

PlatformBox platformBox(const Station& scale) {
  const double t = Workcell::kScalePlatformThickness;
  return {{scale.area.centre.x(), scale.area.centre.y(), scale.surface_z - t / 2},
          {scale.area.size.x(), scale.area.size.y(), t},
          scale.area.yaw};
}

/// Colour of a fixture box, by the type of the station it belongs to.
Eigen::Vector3d fixtureColour(const WorldLayout& l, const FixtureBox& b) {
  const Station* s = l.find(b.station);
  if (s && s->type == StationType::Scale) return l.scale_colours[1] * 0.8;  // housing
  if (s && s->type == StationType::ArchivalCamera) return {0.3, 0.3, 0.32};  // stand
  if (s && (s->type == StationType::Discard || s->type == StationType::Bin)) {
    return {0.45, 0.40, 0.33};  // box walls
  }
  return {0.5, 0.5, 0.5};
}

/// The scale's platform among the collision boxes (its support surface): the simulator's body.
bool isPlatform(const WorldLayout& l, const FixtureBox& b) {
  const Station* s = l.find(b.station);
  return b.is_support && s && s->type == StationType::Scale;
}

struct GeomTag {
  enum Kind { kTable, kStatic, kPlatform, kSherd, kArm, kLeftFinger, kRightFinger } kind;
  int index;
};

void odeInitOnce() {
  static std::once_flag flag;
  std::call_once(flag, [] { dInitODE2(0); });
}

void toOde(const Eigen::Matrix3d& r, dMatrix3 m) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) m[i * 4 + j] = r(i, j);
    m[i * 4 + 3] = 0;
  }
}

Eigen::Isometry3d bodyPose(dBodyID b) {
  const dReal* p = dBodyGetPosition(b);
  const dReal* r = dBodyGetRotation(b);
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) t.linear()(i, j) = r[i * 4 + j];
  }
  t.translation() = Eigen::Vector3d(p[0], p[1], p[2]);
  return t;
}
}  // namespace

struct World::Impl {
  struct Sherd {
    SherdSpec spec;
    SherdGeometry geo;
    dBodyID body = nullptr;
    std::vector<dGeomID> geoms;  // the collision strips, all on `body`
    GeomTag tag{GeomTag::kSherd, 0};
    double ignore_until = -1.0;
    bool ignore_overlap = false;  // arm contacts ignored until no arm box overlaps the sherd
    bool overlap_seen = false;    // an arm box overlapped it in this step
  };

  dWorldID world = nullptr;
  dSpaceID space = nullptr;
  dJointGroupID contact_group = nullptr;
  std::deque<GeomTag> tags;  // stable addresses for dGeomSetData
  dBodyID platform = nullptr;
  dJointID platform_joint = nullptr;
  dJointFeedback platform_feedback{};
  double load = 0.0;
  std::vector<std::unique_ptr<Sherd>> sherds;
  std::vector<dBodyID> link_bodies;  // one per arm link that carries boxes (index = ArmLink)
  std::array<Eigen::Isometry3d, kArmLinkCount> arm_pose, arm_target;
  std::vector<Mesh> link_meshes;     // one per LinkBox
  dJointID hold_joint = nullptr;
  int held = -1;
  FingerContacts contacts_now, contacts_last;
  std::vector<ArmTouch> touches_now, touches_last;
  std::vector<LinkBox> link_boxes;  // the arm's, the fingers with their pads (GripperGeometry::pad)
  Mesh fixtures;
  std::vector<FixtureBox> boxes;  // the layout's collision boxes, where they really stand
  double time = 0.0;

  GeomTag* tag(GeomTag::Kind k, int i) {
    tags.push_back({k, i});
    return &tags.back();
  }

  void staticBox(const Eigen::Vector3d& centre, const Eigen::Vector3d& size, double yaw) {
    dGeomID g = dCreateBox(space, size.x(), size.y(), size.z());
    dGeomSetPosition(g, centre.x(), centre.y(), centre.z());
    dMatrix3 r;
    dRFromAxisAndAngle(r, 0, 0, 1, yaw);
    dGeomSetRotation(g, r);
    dGeomSetData(g, tag(GeomTag::kStatic, 0));
  }

  static void nearCallback(void* data, dGeomID o1, dGeomID o2) {
    static_cast<Impl*>(data)->collide(o1, o2);
  }

  void collide(dGeomID o1, dGeomID o2) {
    dBodyID b1 = dGeomGetBody(o1), b2 = dGeomGetBody(o2);
    const bool dyn1 = b1 && !dBodyIsKinematic(b1), dyn2 = b2 && !dBodyIsKinematic(b2);
    if (!dyn1 && !dyn2) return;
    const GeomTag* t1 = static_cast<const GeomTag*>(dGeomGetData(o1));
    const GeomTag* t2 = static_cast<const GeomTag*>(dGeomGetData(o2));
    if (!t1 || !t2) return;
    if (t2->kind == GeomTag::kSherd && t1->kind != GeomTag::kSherd) {
      std::swap(o1, o2);
      std::swap(b1, b2);
      std::swap(t1, t2);
    }
    if (t1->kind == GeomTag::kPlatform &&
        (t2->kind == GeomTag::kStatic || t2->kind == GeomTag::kTable)) return;
    if (t2->kind == GeomTag::kPlatform &&
        (t1->kind == GeomTag::kStatic || t1->kind == GeomTag::kTable)) return;
    const bool arm2 = t2->kind == GeomTag::kArm || t2->kind == GeomTag::kLeftFinger ||
                      t2->kind == GeomTag::kRightFinger;
    if (t1->kind == GeomTag::kSherd && arm2) {
      const Sherd& s = *sherds[t1->index];
      if (t1->index == held || time < s.ignore_until) return;
    }
    if (t1->kind == GeomTag::kSherd && arm2 && sherds[t1->index]->ignore_overlap) {
      dContactGeom g;
      if (dCollide(o1, o2, 1, &g, sizeof(dContactGeom)) > 0) sherds[t1->index]->overlap_seen = true;
      return;
    }
    if (t1->kind == GeomTag::kSherd && (arm2 || t2->kind == GeomTag::kPlatform) && !dBodyIsEnabled(b1)) {
      dBodyEnable(b1);  // the arm or the pan wakes a sleeping sherd
    }
    dContact c[4];
    const int n = dCollide(o1, o2, 4, &c[0].geom, sizeof(dContact));
    if (n == 0) return;
    double mu = 0.6;
    if (t1->kind == GeomTag::kSherd) {
      if (t2->kind == GeomTag::kLeftFinger || t2->kind == GeomTag::kRightFinger) mu = 1.2;
      else if (t2->kind == GeomTag::kSherd) mu = 0.45;
      else mu = 0.55;
    }
    double depth = 0.0;
    for (int i = 0; i < n; ++i) {
      c[i].surface.mode = dContactApprox1 | dContactSoftERP | dContactSoftCFM;
      c[i].surface.mu = mu;
      c[i].surface.soft_erp = 0.3;
      c[i].surface.soft_cfm = 1e-6;
      dJointID j = dJointCreateContact(world, contact_group, &c[i]);
      dJointAttach(j, b1, b2);
      depth = std::max(depth, static_cast<double>(c[i].geom.depth));
    }
    if (t1->kind == GeomTag::kSherd && arm2) {
      touched(t1->index, t2->index, Eigen::Vector3d(c[0].geom.pos[0], c[0].geom.pos[1], c[0].geom.pos[2]));
    }
    if (t1->kind == GeomTag::kSherd) {
      if (t2->kind == GeomTag::kLeftFinger && depth >= contacts_now.left_depth) {
        contacts_now.left = t1->index;
        contacts_now.left_depth = depth;
      } else if (t2->kind == GeomTag::kRightFinger && depth >= contacts_now.right_depth) {
        contacts_now.right = t1->index;
        contacts_now.right_depth = depth;
      }
    }
  }

  void touched(int sherd, int link, const Eigen::Vector3d& point) {
    for (const ArmTouch& t : touches_now) {
      if (t.sherd == sherd && t.link == link) return;
    }
    touches_now.push_back({sherd, link, point});
  }

  void buildFixtures(const WorldLayout& l) {
    Mesh& m = fixtures;
    m.addRect(0.25, 0.0, 1.3, 1.5, 0.0, l.table_colour);
    const double mz = 0.0004;
    for (const Station& s : l.stations) {
      if (s.type == StationType::Pickup || s.type == StationType::Discard || s.type == StationType::Bin) {
        m.addRect(s.area.centre.x(), s.area.centre.y(), s.area.size.x(), s.area.size.y(), mz, l.mat_colour,
                  s.area.yaw);
      }
    }
    // fixtures standing on the table: scale housing, camera stand post, discard box walls
    for (const FixtureBox& b : boxes) {
      if (!isPlatform(l, b)) m.addBox(b.centre, b.size, fixtureColour(l, b), b.yaw);
    }
    // scale platform: dark rim, light pan
    const Station& scale = l.station(StationType::Scale);
    const PlatformBox pb = platformBox(scale);
    m.addBox(pb.centre, pb.size, l.scale_colours[1], pb.yaw);
    if ((scale.area.size.array() > 0.02).all()) {
      m.addRect(pb.centre.x(), pb.centre.y(), scale.area.size.x() - 0.02, scale.area.size.y() - 0.02,
                scale.surface_z + 0.0003, l.scale_colours[0], pb.yaw);
    }
    // colour chart: black card with 4 x 6 patches, row 1 at +y
    const Station& camera = l.station(StationType::ArchivalCamera);
    const TableRect& cc = camera.colour_chart;
    m.addRect(cc.centre.x(), cc.centre.y(), cc.size.x(), cc.size.y(), 0.0008, {0.05, 0.05, 0.05}, cc.yaw);
    const auto patches = MunsellTable::readColourChecker(l.data_dir + "/colorchecker24_xrite_after2014_D50.csv");
    const double pw = cc.size.x() / 6, ph = cc.size.y() / 4;
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 6; ++c) {
        const Eigen::Vector2d p =
            cc.toTable({-cc.size.x() / 2 + (c + 0.5) * pw, cc.size.y() / 2 - (r + 0.5) * ph});
        m.addRect(p.x(), p.y(), pw * 0.8, ph * 0.8, 0.0012, patches[r * 6 + c], cc.yaw);
      }
    }
    // scale bar: 10 cm, two rows; -x half a 1 cm chequer, +x half black over white
    const TableRect& sb = camera.scale_bar;
    const double row = sb.size.y() / 2, cell = sb.size.x() / 10;
    for (int i = 0; i < 10; ++i) {
      for (int r = 0; r < 2; ++r) {
        const Eigen::Vector2d p = sb.toTable({-sb.size.x() / 2 + (i + 0.5) * cell, r == 0 ? row / 2 : -row / 2});
        const bool black = i < 5 ? ((i + r) % 2 == 0) : (r == 0);
        m.addRect(p.x(), p.y(), cell, row, 0.0008,
                  black ? Eigen::Vector3d(0.04, 0.04, 0.04) : Eigen::Vector3d(0.95, 0.95, 0.95), sb.yaw);
      }
    }
    // camera stand: boom from the post and camera body above the lens (the post is a fixture box)
    const double lens = camera.camera_height;
    // the boom runs from the post to above the field of view's centre
    const Eigen::Vector2d lens_at = camera.area.centre, post = camera.stand.centre;
    const Eigen::Vector2d boom = (lens_at + post) / 2, along = post - lens_at;
    m.addBox({boom.x(), boom.y(), lens + 0.06}, {along.norm(), 0.03, 0.02}, {0.3, 0.3, 0.32},
             std::atan2(along.y(), along.x()));
    m.addBox({lens_at.x(), lens_at.y(), lens + 0.035}, {0.11, 0.07, 0.07}, {0.08, 0.08, 0.08}, camera.area.yaw);
    for (const StationMarker& k : l.markers) k.draw(m);
  }

  void buildPlatform(const Station& scale) {
    const PlatformBox pb = platformBox(scale);
    platform = dBodyCreate(world);
    dMass m;
    dMassSetBoxTotal(&m, kPlatformMass, pb.size.x(), pb.size.y(), pb.size.z());
    dBodySetMass(platform, &m);
    dBodySetPosition(platform, pb.centre.x(), pb.centre.y(), pb.centre.z());
    dMatrix3 r;
    dRFromAxisAndAngle(r, 0, 0, 1, pb.yaw);
    dBodySetRotation(platform, r);
    dBodySetAutoDisableFlag(platform, 0);
    dGeomID pg = dCreateBox(space, pb.size.x(), pb.size.y(), pb.size.z());
    dGeomSetBody(pg, platform);
    dGeomSetData(pg, tag(GeomTag::kPlatform, 0));
    platform_joint = dJointCreateFixed(world, nullptr);
    dJointAttach(platform_joint, platform, nullptr);
    dJointSetFixed(platform_joint);
    dJointSetFeedback(platform_joint, &platform_feedback);
  }

  void buildPhysics(const WorldLayout& l) {
    dGeomID plane = dCreatePlane(space, 0, 0, 1, 0);
    dGeomSetData(plane, tag(GeomTag::kTable, 0));
    // static fixtures in the workcell's order; the platform is a body of its own (the scale's
    // load is its joint's support force)
    for (const FixtureBox& b : boxes) {
      if (isPlatform(l, b)) {
        buildPlatform(l.station(StationType::Scale));
      } else {
        staticBox(b.centre, b.size, b.yaw);
      }
    }
    if (!platform) buildPlatform(l.station(StationType::Scale));  // a scale at table height
    // arm: one kinematic body per link that carries boxes
    link_bodies.assign(kArmLinkCount, nullptr);
    for (const LinkBox& b : link_boxes) {
      if (!link_bodies[b.link]) {
        link_bodies[b.link] = dBodyCreate(world);
        dBodySetKinematic(link_bodies[b.link]);
        dBodySetAutoDisableFlag(link_bodies[b.link], 0);
      }
      dGeomID g = dCreateBox(space, b.size.x(), b.size.y(), b.size.z());
      dGeomSetBody(g, link_bodies[b.link]);
      dGeomSetOffsetPosition(g, b.offset.translation().x(), b.offset.translation().y(), b.offset.translation().z());
      dMatrix3 r;
      toOde(b.offset.linear(), r);
      dGeomSetOffsetRotation(g, r);
      GeomTag::Kind k = b.link == kLeftFingerLink ? GeomTag::kLeftFinger
                        : b.link == kRightFingerLink ? GeomTag::kRightFinger : GeomTag::kArm;
      dGeomSetData(g, tag(k, b.link));
      Mesh lm;
      lm.addBox(Eigen::Vector3d::Zero(), b.size, b.srgb);
      lm.cull_back_faces = true;
      lm.updateBounds();
      link_meshes.push_back(lm);
    }
  }

  void setLinkBodies(bool with_velocity, double dt) {
    for (int i = 0; i < kArmLinkCount; ++i) {
      dBodyID b = link_bodies[i];
      if (!b) continue;
      const Eigen::Isometry3d& now = arm_pose[i];
      const Eigen::Isometry3d& next = arm_target[i];
      if (with_velocity) {
        const Eigen::Vector3d v = (next.translation() - now.translation()) / dt;
        const Eigen::AngleAxisd aa(next.linear() * now.linear().transpose());
        const Eigen::Vector3d w = aa.axis() * (aa.angle() / dt);
        dBodySetLinearVel(b, v.x(), v.y(), v.z());
        dBodySetAngularVel(b, w.x(), w.y(), w.z());
      } else {
        dBodySetPosition(b, next.translation().x(), next.translation().y(), next.translation().z());
        dMatrix3 r;
        toOde(next.linear(), r);
        dBodySetRotation(b, r);
      }
    }
  }
};

World::World(const WorldLayout& layout, const rascal_workcell::GripperGeometry& gripper, double start_time)
    : impl_(new Impl), layout_(layout), time_(start_time) {
  odeInitOnce();
  Impl& w = *impl_;
  w.world = dWorldCreate();
  dWorldSetGravity(w.world, 0, 0, -kGravity);
  dWorldSetERP(w.world, 0.2);
  dWorldSetCFM(w.world, 1e-7);
  dWorldSetQuickStepNumIterations(w.world, 20);
  dWorldSetContactMaxCorrectingVel(w.world, 0.2);
  dWorldSetContactSurfaceLayer(w.world, 0.0002);
  // sherds at rest sleep until something touches them (the pan and the arm never sleep)
  dWorldSetAutoDisableFlag(w.world, 1);
  dWorldSetAutoDisableLinearThreshold(w.world, 0.002);
  dWorldSetAutoDisableAngularThreshold(w.world, 0.02);
  dWorldSetAutoDisableSteps(w.world, 50);
  dWorldSetAutoDisableTime(w.world, 0);
  w.space = dHashSpaceCreate(nullptr);
  w.contact_group = dJointGroupCreate(0);
  w.boxes = layout.boxes;
  w.link_boxes = ArmKinematics::linkBoxes(gripper.pad);
  w.buildFixtures(layout);
  w.fixtures.cull_back_faces = true;  // boxes wound outwards, rectangles face up
  w.fixtures.updateBounds();
  w.buildPhysics(layout);
  JointVector q{0.0, -1.80, 1.55, 0.0, 0.8, 0.0};
  placeArm(q, gripper.finger_max);
}

World::~World() {
  Impl& w = *impl_;
  clearSherds();
  dJointGroupDestroy(w.contact_group);
  dSpaceDestroy(w.space);
  dWorldDestroy(w.world);
}

void World::clearSherds() {
  Impl& w = *impl_;
  release();
  for (auto& s : w.sherds) {
    for (dGeomID g : s->geoms) dGeomDestroy(g);
    dBodyDestroy(s->body);
  }
  w.sherds.clear();
  w.contacts_last = FingerContacts();
  w.touches_last.clear();
}

void World::seedSolver(unsigned long seed) { dRandSetSeed(seed); }

void World::spawn(const std::vector<SherdSpec>& sherds) {
  dAllocateODEDataForThread(dAllocateMaskAll);  // spawn may come from a service thread
  clearSherds();
  Impl& w = *impl_;
  for (size_t i = 0; i < sherds.size(); ++i) {
    auto s = std::make_unique<Impl::Sherd>();
    s->spec = sherds[i];
    s->geo = SherdMeshBuilder::build(s->spec);
    if (s->geo.mass <= 0.0) throw std::runtime_error("sherd " + s->spec.name + " has no volume");
    const Eigen::Vector3d& size = s->geo.box_size;
    s->body = dBodyCreate(w.world);
    dMass m;
    dMassSetBoxTotal(&m, s->geo.mass, size.x(), size.y(), size.z());
    dBodySetMass(s->body, &m);
    const double x = s->spec.pose.x(), y = s->spec.pose.y();
    double support = 0.0;  // the table, or a support surface (the scale platform) under it
    for (const FixtureBox& b : w.boxes) {
      if (b.is_support && b.footprint().contains({x, y})) {
        support = std::max(support, b.centre.z() + b.size.z() / 2);
      }
    }
    const double tilt = s->spec.tilt;
    const double tall = std::abs(size.y() * std::sin(tilt)) + std::abs(size.z() * std::cos(tilt));
    dBodySetPosition(s->body, x, y, support + tall / 2 + s->spec.drop_height + 1e-4);
    const Eigen::Matrix3d R = (Eigen::AngleAxisd(s->spec.pose.z(), Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitX()))
                                  .toRotationMatrix();
    dMatrix3 r;
    toOde(R, r);
    dBodySetRotation(s->body, r);
    dBodySetLinearDamping(s->body, 0.001);
    dBodySetAngularDamping(s->body, 0.01);
    s->tag.index = static_cast<int>(i);
    for (const CollisionBox& c : s->geo.collision) {
      dGeomID g = dCreateBox(w.space, c.size.x(), c.size.y(), c.size.z());
      dGeomSetBody(g, s->body);
      dGeomSetOffsetPosition(g, c.centre.x(), c.centre.y(), c.centre.z());
      dGeomSetData(g, &s->tag);
      s->geoms.push_back(g);
    }
    w.sherds.push_back(std::move(s));
  }
}

void World::placeArm(const JointVector& q, double finger) {
  Impl& w = *impl_;
  release();
  w.arm_pose = ArmKinematics::forward(q, finger);
  w.arm_target = w.arm_pose;
  w.setLinkBodies(false, 1.0);
  for (dBodyID b : w.link_bodies) {
    if (!b) continue;
    dBodySetLinearVel(b, 0, 0, 0);
    dBodySetAngularVel(b, 0, 0, 0);
  }
}

void World::setArmTarget(const JointVector& q, double finger) {
  impl_->arm_target = ArmKinematics::forward(q, finger);
}

void World::step(double dt) {
  Impl& w = *impl_;
  w.time = time_;
  w.setLinkBodies(true, dt);
  w.contacts_now = FingerContacts();
  w.touches_now.clear();
  for (auto& s : w.sherds) s->overlap_seen = false;
  dSpaceCollide(w.space, &w, &Impl::nearCallback);
  for (auto& s : w.sherds) s->ignore_overlap = s->ignore_overlap && s->overlap_seen;
  dWorldQuickStep(w.world, dt);
  dJointGroupEmpty(w.contact_group);
  w.setLinkBodies(false, dt);
  w.arm_pose = w.arm_target;
  w.contacts_last = w.contacts_now;
  std::swap(w.touches_last, w.touches_now);
  w.load = w.platform_feedback.f1[2] / kGravity - kPlatformMass;
  // the pan is fixed to the world: keep numerical drift out of it
  time_ += dt;
}

double World::scaleLoad() const { return impl_->load; }

const FingerContacts& World::fingerContacts() const { return impl_->contacts_last; }

const std::vector<ArmTouch>& World::armTouches() const { return impl_->touches_last; }

void World::hold(int sherd) {
  Impl& w = *impl_;
  if (w.held == sherd || sherd < 0 || sherd >= static_cast<int>(w.sherds.size())) return;
  release();
  dBodyEnable(w.sherds[sherd]->body);
  dBodySetAutoDisableFlag(w.sherds[sherd]->body, 0);  // follows the gripper even when it stops
  w.hold_joint = dJointCreateFixed(w.world, nullptr);
  dJointAttach(w.hold_joint, w.sherds[sherd]->body, w.link_bodies[kGripperLink]);
  dJointSetFixed(w.hold_joint);
  w.held = sherd;
}

void World::release() {
  Impl& w = *impl_;
  if (w.hold_joint) dJointDestroy(w.hold_joint);
  if (w.held >= 0 && w.held < static_cast<int>(w.sherds.size())) {
    dBodySetAutoDisableFlag(w.sherds[w.held]->body, 1);
    dBodyEnable(w.sherds[w.held]->body);
  }
  w.hold_joint = nullptr;
  w.held = -1;
}

int World::held() const { return impl_->held; }

void World::ignoreGripperContacts(int sherd, double until) {
  if (sherd >= 0 && sherd < static_cast<int>(impl_->sherds.size())) impl_->sherds[sherd]->ignore_until = until;
}

void World::ignoreGripperContactsWhileOverlapping(int sherd) {
  if (sherd < 0 || sherd >= static_cast<int>(impl_->sherds.size())) return;
  impl_->sherds[sherd]->ignore_overlap = true;
  impl_->sherds[sherd]->overlap_seen = true;
}

void World::stopIgnoringOverlaps() {
  for (auto& s : impl_->sherds) s->ignore_overlap = false;
}

size_t World::sherdCount() const { return impl_->sherds.size(); }

SherdState World::sherd(size_t i) const {
  const Impl::Sherd& s = *impl_->sherds.at(i);
  SherdState st;
  st.name = s.spec.name;
  st.pose = bodyPose(s.body);
  const dReal* v = dBodyGetLinearVel(s.body);
  const dReal* a = dBodyGetAngularVel(s.body);
  st.linear_velocity = Eigen::Vector3d(v[0], v[1], v[2]);
  st.angular_velocity = Eigen::Vector3d(a[0], a[1], a[2]);
  st.mass = s.geo.mass;
  st.thickness = s.spec.mesh_file.empty() ? s.spec.thickness : s.geo.box_size.z();
  st.curvature = s.spec.mesh_file.empty() ? s.spec.curvature : 0.0;
  st.curvature_long = s.spec.mesh_file.empty() ? s.spec.curvature_long : 0.0;
  st.convex_up = s.spec.convex_up;
  st.length = s.geo.length;
  st.width = s.geo.width;
  st.box_size = s.geo.box_size;
  st.outline = s.geo.outline;
  st.colour = s.spec.colour;
  st.held = static_cast<int>(i) == impl_->held;
  return st;
}

const std::array<Eigen::Isometry3d, kArmLinkCount>& World::armPose() const { return impl_->arm_pose; }

void World::renderItems(std::vector<RenderItem>& items, bool include_arm) const {
  const Impl& w = *impl_;
  items.clear();
  items.push_back({&w.fixtures, Eigen::Isometry3d::Identity(), 1});
  for (size_t i = 0; i < w.sherds.size(); ++i) {
    items.push_back({&w.sherds[i]->geo.mesh, bodyPose(w.sherds[i]->body), static_cast<int>(10 + i)});
  }
  if (!include_arm) return;
  const auto& boxes = w.link_boxes;
  for (size_t i = 0; i < boxes.size(); ++i) {
    items.push_back({&w.link_meshes[i], w.arm_pose[boxes[i].link] * boxes[i].offset, 2});
  }
}

}  // namespace rascal_sim
