-- RASCAL catalogue, version 9: the box a sherd was put into (issue 17, sorting): the discard
-- station's name, or the sorting bin (a station of type bin) whose rule took it. Empty for
-- sherds recorded before sorting existed and for sherds not yet sorted. The `sorted` event
-- keeps the rule's reason. Migrate a central server before its rigs: logical replication needs
-- the column on the subscriber first.
ALTER TABLE sherds
    ADD COLUMN bin text CHECK (bin ~ '^[A-Za-z0-9_]{1,64}$');
