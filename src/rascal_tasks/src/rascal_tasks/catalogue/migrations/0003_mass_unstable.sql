-- RASCAL catalogue, version 3: a sherd the scale could not weigh is recorded, not guessed.
-- Status mass_unstable takes the place of weighed when no reading held steady (or the scale could
-- not be tared): the row has no mass, and mass_missing_reason says why. Such a sherd is still
-- photographed and discarded; the reason stays with the row when it moves on to photographed and
-- done, so a done row has a mass or says why it has none, never both.
-- The new enum value cannot be used in this transaction (PostgreSQL), so the checks below compare
-- status as text.

ALTER TYPE sherd_status ADD VALUE IF NOT EXISTS 'mass_unstable' AFTER 'picked';

ALTER TABLE sherds
    ADD COLUMN mass_missing_reason text CHECK (mass_missing_reason <> ''),
    DROP CONSTRAINT sherds_weighed_has_mass,
    ADD CONSTRAINT sherds_weighed_has_mass CHECK (status::text <> 'weighed' OR mass_g IS NOT NULL),
    ADD CONSTRAINT sherds_mass_unstable_has_reason CHECK (
        status::text <> 'mass_unstable' OR (mass_g IS NULL AND mass_missing_reason IS NOT NULL)),
    ADD CONSTRAINT sherds_past_scale_has_mass_or_reason CHECK (
        status::text NOT IN ('photographed', 'done')
        OR mass_g IS NOT NULL OR mass_missing_reason IS NOT NULL),
    ADD CONSTRAINT sherds_mass_or_reason CHECK (mass_g IS NULL OR mass_missing_reason IS NULL);

-- the unfinished sherds, mass_unstable included (named by the final states: see above)
DROP INDEX sherds_unfinished;
CREATE INDEX sherds_unfinished ON sherds (context_id, seq) WHERE status NOT IN ('done', 'lost');
