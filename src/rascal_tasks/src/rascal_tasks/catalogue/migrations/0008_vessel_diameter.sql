-- RASCAL catalogue, version 8: the vessel's outer diameter estimated from the sherd's curvature
-- (rascal_perception ShellFit: the strongest curvature of the top surface seen by the wrist
-- camera's depth), with its 1-sigma uncertainty. Empty when the sherd is too flat or too small
-- to tell, or curved both ways alike. Migrate a central server before its rigs: logical
-- replication needs the columns on the subscriber first.
ALTER TABLE sherds
    ADD COLUMN vessel_diameter_mm        double precision CHECK (vessel_diameter_mm > 0),
    ADD COLUMN vessel_diameter_sigma_mm  double precision CHECK (vessel_diameter_sigma_mm > 0),
    ADD CONSTRAINT sherds_diameter_has_sigma CHECK (
        (vessel_diameter_mm IS NULL) = (vessel_diameter_sigma_mm IS NULL));
