-- Every job lists its meshes in one column (a JSON array of mesh ids, in the spec's order:
-- source, target for pair jobs); `spec` holds the typed JobSpec alone. `source` and `target`
-- stay as the first and last mesh.
ALTER TABLE jobs ADD COLUMN meshes TEXT NOT NULL DEFAULT '[]';
-- Jobs stored before: N-mesh jobs carried their ids in a {"meshes", "spec"} envelope.
UPDATE jobs SET meshes = (spec::jsonb -> 'meshes')::text, spec = (spec::jsonb -> 'spec')::text
    WHERE jsonb_typeof(spec::jsonb -> 'meshes') = 'array';
UPDATE jobs SET meshes = jsonb_build_array(source, target)::text WHERE meshes = '[]';
