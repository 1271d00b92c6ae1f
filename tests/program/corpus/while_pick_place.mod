MODULE WhilePickPlace
    ! WHILE TRUE around a pick-and-place with WaitTime (cycle --use-waits crashed on it).
    PERS tooldata tGripper := [TRUE, [[0, 0, 90], [1, 0, 0, 0]], [0.6, [0, 0, 45], [1, 0, 0, 0], 0, 0, 0]];
    CONST jointtarget jHome := [[0, 0, 0, 0, 30, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pAbovePick := [[175, -375, 280], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pPick := [[175, -375, 140], [0, 0, 1, 0], [-1, 0, -1, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pAbovePlace := [[380, 175, 310], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];
    CONST robtarget pPlace := [[380, 175, 165], [0, 0, 1, 0], [0, 0, 0, 0], [9E9, 9E9, 9E9, 9E9, 9E9, 9E9]];

    PROC main()
        MoveAbsJ jHome, v1000, fine, tGripper;
        WHILE TRUE DO
            MoveJ pAbovePick, v1000, z50, tGripper;
            MoveL pPick, v300, fine, tGripper;
            WaitTime 0.3;
            MoveL pAbovePick, v300, z20, tGripper;
            MoveJ pAbovePlace, v1000, z20, tGripper;
            MoveL pPlace, v200, fine, tGripper;
            WaitTime 0.3;
            MoveL pAbovePlace, v500, z20, tGripper;
            MoveAbsJ jHome, v1000, fine, tGripper;
            WaitTime 1.0;
        ENDWHILE
    ENDPROC
ENDMODULE
