MODULE PickAndPlace
    ! A pick-and-place cycle for the ABB IRB 120 (joulepath example).
    ! The robot takes a part from the infeed on its right, lifts it over the
    ! via point, places it on the fixture in front of it and returns.
    ! Targets are TCP poses of tGripper in the base frame (mm, quaternion w-first).
    PERS tooldata tGripper := [TRUE, [[0, 0, 90], [1, 0, 0, 0]], [0.6, [0, 0, 45], [1, 0, 0, 0], 0, 0, 0]];
    CONST jointtarget jHome := [[0, 0, 0, 0, 30, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pAbovePick := [[175, -375, 280], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pPick := [[175, -375, 140], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pVia := [[350, -130, 500], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pAbovePlace := [[380, 175, 310], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pPlace := [[380, 175, 165], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST num GRIP_TIME := 0.3;
    VAR num nParts := 0;

    PROC main()
        MoveAbsJ jHome, v1000, fine, tGripper;
        WHILE TRUE DO
            MoveJ pAbovePick, v1000, z50, tGripper;
            MoveL pPick, v300, fine, tGripper;
            WaitTime GRIP_TIME;
            MoveL pAbovePick, v300, z20, tGripper;
            MoveJ pVia, v1000, z50, tGripper;
            Place;
            MoveAbsJ jHome, v1000, fine, tGripper;
            nParts := nParts + 1;
        ENDWHILE
    ENDPROC

    PROC Place()
        MoveJ pAbovePlace, v1000, z20, tGripper;
        MoveJ pPlace, v200, fine, tGripper;
        WaitTime GRIP_TIME;
        MoveJ pAbovePlace, v500, z20, tGripper;
    ENDPROC
ENDMODULE
