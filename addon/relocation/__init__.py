"""Moving a photographed object under the fixed-view constraint: the move (`fixedview`), where
it lands (`placement`), and the removal at the old place with the insertion at the new one
(`insertion`), which carries the object's appearance (`appearance`)."""
