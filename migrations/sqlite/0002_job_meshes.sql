-- Every job lists its meshes in one column (a JSON array of mesh ids, in the spec's order:
-- source, target for pair jobs); `spec` holds the typed JobSpec alone. `source` and `target`
-- stay as the first and last mesh.
ALTER TABLE jobs ADD COLUMN meshes TEXT NOT NULL DEFAULT '[]';
-- Jobs stored before: N-mesh jobs carried their ids in a {"meshes", "spec"} envelope.
UPDATE jobs SET meshes = json_extract(spec, '$.meshes'), spec = json_extract(spec, '$.spec')
    WHERE json_valid(spec) AND json_type(spec, '$.meshes') = 'array';
UPDATE jobs SET meshes = json_array(source, target) WHERE meshes = '[]';
