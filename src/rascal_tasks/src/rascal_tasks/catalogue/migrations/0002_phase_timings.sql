-- RASCAL catalogue, version 2: time per sherd broken down as in the RASCAL paper (Fig. 10):
-- locomotion (arm moves), grasping (gripper strokes, grasp checks), data collection (scale
-- settling, shutter, transfers) and perception (detection). Seconds of the rig's clock
-- (simulated seconds on the simulator); written when the sherd is done or lost.
ALTER TABLE sherds
    ADD COLUMN t_locomotion_s       double precision CHECK (t_locomotion_s >= 0),
    ADD COLUMN t_grasping_s         double precision CHECK (t_grasping_s >= 0),
    ADD COLUMN t_data_collection_s  double precision CHECK (t_data_collection_s >= 0),
    ADD COLUMN t_perception_s       double precision CHECK (t_perception_s >= 0);
