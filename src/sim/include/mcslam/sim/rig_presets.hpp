#pragma once
// Rig presets and how a rig is mounted on the simulated platform.
//
//  isec    the paper's rig (section VI-A): the five front cameras of the ISEC calibration (720x540, radtan,
//          baselines about 0.165 m) plus two cameras looking left and right, mounted near the middle of the
//          rig and rotated -+90 degrees about its vertical axis (same intrinsics as the centre camera): cam5 left,
//          cam6 right. 7 cameras; cams 0-4 overlap, {2, 5, 6} do not.
//  stereo  cams 0 and 1 of the ISEC calibration (baseline 0.165 m).
//  mono    the ISEC centre camera (cam2).
//  ring8   eight equidistant fisheyes (720x540, about 160 degrees horizontally, corners beyond 90 degrees) on a
//          ring of radius 0.12 m around the vertical axis, 45 degrees apart; neighbours overlap.
// The body frame of every preset is its cam0 (as Kalibr files give it).
#include <string>
#include <vector>

#include "mcslam/calib/rig.hpp"

namespace mcslam::sim {

std::vector<std::string> rigPresetNames();
std::string describeRigPresets();  // one line per preset, for --help
// Throws InputError naming the unknown preset and listing the known ones.
Rig makePresetRig(const std::string& name);
// A preset name, or else the path of a Kalibr camchain file (errors name the file and field).
Rig loadRig(const std::string& preset_or_path);

// Pose of the rig body in the platform frame (x forward, y left, z up, origin on the rig's centre), T_v_b:
// cam0 looks forward along x with its image rows horizontal, and the mean of the camera centres sits at the
// platform origin. Trajectories move the platform; T_w_b = T_w_v * T_v_b.
SE3 rigMount(const Rig& rig);

}  // namespace mcslam::sim
